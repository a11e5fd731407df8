#include "eval/pose_accuracy.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "eval/align.h"
#include "eval/metrics.h"

namespace rigc::eval {

using nlohmann::json;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kFailedPairDeg = 180;

double angle_between_deg(const Vec3& a, const Vec3& b) {
  const double na = a.norm(), nb = b.norm();
  if (na == 0 || nb == 0) return 0;
  return std::acos(std::clamp(a.dot(b) / (na * nb), -1.0, 1.0)) * 180 / M_PI;
}

// tgt_from_src = tgt * src^-1 of two camera_from_world poses.
Mat4 relative_pose(const Mat4& src, const Mat4& tgt) {
  Mat4 src_inverse = Mat4::Identity();
  src_inverse.topLeftCorner<3, 3>() = src.topLeftCorner<3, 3>().transpose();
  src_inverse.topRightCorner<3, 1>() =
      -src.topLeftCorner<3, 3>().transpose() * src.topRightCorner<3, 1>();
  return tgt * src_inverse;
}

double relative_pose_error_deg(const Mat4& est, const Mat4& gt) {
  const Eigen::Matrix3d dr = est.topLeftCorner<3, 3>().transpose() * gt.topLeftCorner<3, 3>();
  const double rotation = rotation_angle_deg(dr);
  const double translation =
      angle_between_deg(est.topRightCorner<3, 1>(), gt.topRightCorner<3, 1>());
  return std::max(rotation, translation);
}

// fx of any COLMAP camera model (f or fx comes first), scaled to `width` pixels.
double focal_px(const run::ColmapCamera& c, int width) {
  if (c.params.empty()) return kNaN;
  const double scale = (width > 0 && c.width > 0) ? static_cast<double>(width) / c.width : 1;
  return c.params.front() * scale;
}

json stats_json(std::vector<double> values) {
  std::erase_if(values, [](double v) { return !std::isfinite(v); });
  if (values.empty()) return nullptr;
  const DistanceStats s = distance_stats(values);
  return {{"mean", s.mean}, {"median", s.median}, {"max", s.max}};
}

// The similarity that takes the estimated centres onto the reference ones: RANSAC (a threshold
// of 2 % of the reference ring's spread) then least squares on the inliers.
std::optional<RobustSimilarity> fit_centres(const std::vector<Vec3>& estimated,
                                            const std::vector<Vec3>& reference) {
  Vec3 centroid = Vec3::Zero();
  for (const auto& r : reference) centroid += r;
  centroid /= std::max<std::size_t>(1, reference.size());
  double spread = 0;
  for (const auto& r : reference) spread += (r - centroid).squaredNorm();
  spread = std::sqrt(spread / std::max<std::size_t>(1, reference.size()));
  return fit_similarity_ransac(estimated, reference, std::max(0.02 * spread, 1e-9), 2000, 1);
}

PhotoPoseError photo_error(const std::string& name, const KnownCamera& ref, const Mat4& est,
                           const Similarity& align, const Vec3& object,
                           const run::ColmapCamera* est_intrinsics) {
  PhotoPoseError e;
  e.name = name;
  e.registered = true;
  const Vec3 ref_centre = camera_centre(ref.camera_from_world);
  e.centre_m = (align.apply(camera_centre(est)) - ref_centre).norm();
  const double distance = (ref_centre - object).norm();
  e.centre_percent = distance > 0 ? 100 * e.centre_m / distance : kNaN;
  const Eigen::Matrix3d est_in_ref = est.topLeftCorner<3, 3>() * align.rotation.transpose();
  e.rotation_deg =
      rotation_angle_deg(ref.camera_from_world.topLeftCorner<3, 3>() * est_in_ref.transpose());
  e.focal_percent = kNaN;
  if (ref.intrinsics && est_intrinsics) {
    const int width = ref.intrinsics->width;
    const double f_ref = focal_px(*ref.intrinsics, width);
    const double f_est = focal_px(*est_intrinsics, width);
    if (f_ref > 0) e.focal_percent = 100 * (f_est - f_ref) / f_ref;
  }
  return e;
}

json photos_json(const std::vector<PhotoPoseError>& photos) {
  json list = json::array();
  for (const auto& p : photos) {
    json j = {{"name", p.name}, {"registered", p.registered}};
    if (p.registered) {
      j["rotation_error_deg"] = p.rotation_deg;
      j["centre_error_mm"] = 1000 * p.centre_m;
      j["centre_error_percent_of_distance"] = p.centre_percent;
      if (std::isfinite(p.focal_percent)) j["focal_length_error_percent"] = p.focal_percent;
    }
    list.push_back(std::move(j));
  }
  return list;
}

}  // namespace

std::vector<double> relative_pose_errors(const std::vector<std::string>& names,
                                         const KnownCameras& reference,
                                         const std::map<std::string, Mat4>& estimated) {
  std::vector<double> errors;
  for (const auto& src : names) {
    for (const auto& tgt : names) {
      if (src == tgt) continue;
      const auto es = estimated.find(src), et = estimated.find(tgt);
      if (es == estimated.end() || et == estimated.end()) {
        errors.push_back(kFailedPairDeg);
        continue;
      }
      const Mat4 gt =
          relative_pose(reference.at(src).camera_from_world, reference.at(tgt).camera_from_world);
      errors.push_back(relative_pose_error_deg(relative_pose(es->second, et->second), gt));
    }
  }
  return errors;
}

std::vector<double> pose_auc(std::vector<double> errors, const std::vector<double>& thresholds) {
  std::vector<double> aucs(thresholds.size(), 0);
  if (errors.empty()) return aucs;
  std::sort(errors.begin(), errors.end());
  const double n = static_cast<double>(errors.size());
  for (std::size_t k = 0; k < thresholds.size(); ++k) {
    const double t = thresholds[k];
    // The curve from (0, 0) through (e_i, (i + 1) / n), held flat to t.
    double area = 0, e_prev = 0, r_prev = 0;
    for (std::size_t i = 0; i < errors.size() && errors[i] <= t; ++i) {
      const double r = (static_cast<double>(i) + 1) / n;
      area += (errors[i] - e_prev) * (r_prev + r) / 2;
      e_prev = errors[i];
      r_prev = r;
    }
    area += (t - e_prev) * r_prev;
    aucs[k] = 100 * area / t;
  }
  return aucs;
}

std::optional<Vec3> point_nearest_axes(const std::vector<Mat4>& camera_from_world) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Vec3 b = Vec3::Zero();
  for (const auto& pose : camera_from_world) {
    const Vec3 axis = pose.topLeftCorner<3, 3>().row(2).transpose().normalized();
    const Eigen::Matrix3d off_axis = Eigen::Matrix3d::Identity() - axis * axis.transpose();
    a += off_axis;
    b += off_axis * camera_centre(pose);
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(a);
  const auto& s = svd.singularValues();
  if (camera_from_world.size() < 2 || !(s(2) > 1e-6 * s(0))) return std::nullopt;
  return Vec3(a.ldlt().solve(b));
}

PoseAccuracy measure_pose_accuracy(
    const std::vector<std::string>& names, const KnownCameras& reference,
    const std::map<std::string, Mat4>& estimated,
    const std::map<std::string, run::ColmapCamera>& estimated_intrinsics) {
  PoseAccuracy acc;
  std::vector<Vec3> src, dst;
  std::vector<Mat4> reference_poses;
  for (const auto& name : names) {
    const Mat4& ref = reference.at(name).camera_from_world;
    reference_poses.push_back(ref);
    if (const auto it = estimated.find(name); it != estimated.end()) {
      src.push_back(camera_centre(it->second));
      dst.push_back(camera_centre(ref));
    }
  }
  const auto fit = fit_centres(src, dst);
  if (!fit) {
    acc.failure = fmt::format(
        "cannot fit the reconstruction to the reference cameras: {} registered photos have one "
        "(3 with distinct centres are needed)",
        src.size());
    return acc;
  }
  acc.reference_from_reconstruction = fit->transform;
  const auto centre = point_nearest_axes(reference_poses);
  acc.object_centre = centre ? *centre : Vec3::Zero();
  if (!centre) {
    for (const auto& pose : reference_poses) acc.object_centre += camera_centre(pose);
    acc.object_centre /= static_cast<double>(reference_poses.size());
  }
  std::vector<double> rotation, centre_mm, centre_percent, focal;
  for (const auto& name : names) {
    const auto it = estimated.find(name);
    if (it == estimated.end()) {
      acc.photos.push_back({name, false, kNaN, kNaN, kNaN, kNaN});
      continue;
    }
    const auto intr = estimated_intrinsics.find(name);
    acc.photos.push_back(photo_error(name, reference.at(name), it->second, fit->transform,
                                     acc.object_centre,
                                     intr == estimated_intrinsics.end() ? nullptr : &intr->second));
    const PhotoPoseError& p = acc.photos.back();
    rotation.push_back(p.rotation_deg);
    centre_mm.push_back(1000 * p.centre_m);
    centre_percent.push_back(p.centre_percent);
    focal.push_back(std::abs(p.focal_percent));
  }
  const std::vector<double> thresholds(PoseAccuracy::kAucThresholdsDeg.begin(),
                                       PoseAccuracy::kAucThresholdsDeg.end());
  const std::vector<double> auc =
      pose_auc(relative_pose_errors(names, reference, estimated), thresholds);
  std::copy(auc.begin(), auc.end(), acc.auc.begin());
  json auc_json;
  for (std::size_t k = 0; k < thresholds.size(); ++k) {
    auc_json[fmt::format("{:g}", thresholds[k])] = auc[k];
  }
  acc.report = {
      {"compared", names.size()},
      {"registered", src.size()},
      {"alignment",
       {{"method", "Umeyama similarity in RANSAC on camera centres"},
        {"inliers", fit->inliers.size()},
        {"scale", fit->transform.scale},
        {"rms_centre_error_mm", 1000 * fit->rms_inlier_error}}},
      {"object_centre", {acc.object_centre.x(), acc.object_centre.y(), acc.object_centre.z()}},
      {"rotation_error_deg", stats_json(rotation)},
      {"centre_error_mm", stats_json(centre_mm)},
      {"centre_error_percent_of_distance", stats_json(centre_percent)},
      {"abs_focal_length_error_percent", stats_json(focal)},
      {"relative_pose_auc_percent", auc_json},
      {"auc_definition",
       "COLMAP's benchmark: over every ordered pair of photos, max(rotation error, angle between "
       "the relative translations) in degrees, 180 for a pair with an unregistered photo; the "
       "area under the recall curve up to each threshold"},
      {"photos", photos_json(acc.photos)}};
  acc.ok = true;
  return acc;
}

}  // namespace rigc::eval
