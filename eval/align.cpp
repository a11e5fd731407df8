#include "eval/align.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <utility>

namespace rigc::eval {

using nlohmann::json;

Eigen::AlignedBox3d object_crop(const Surface& surface) {
  const Eigen::AlignedBox3d box = surface.bounds();
  const double diag = box.diagonal().norm();
  Eigen::AlignedBox3d crop = box;
  crop.extend(box.min() - Vec3::Constant(0.05 * diag));
  crop.extend(box.max() + Vec3::Constant(0.05 * diag));
  return crop;
}

std::vector<Vec3> points_inside(const std::vector<Vec3>& points, const Eigen::AlignedBox3d& box,
                                std::size_t limit, std::vector<std::size_t>* indices) {
  // Counted per block first, so that each block writes its share straight into the output.
  const std::size_t block = 1 << 16, blocks = (points.size() + block - 1) / block;
  std::vector<std::size_t> first_rank(blocks + 1, 0);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
    std::size_t n = 0;
    for (std::size_t i = b * block; i < std::min(points.size(), (b + 1) * block); ++i) {
      n += box.contains(points[i]);
    }
    first_rank[b + 1] = n;
  });
  for (std::size_t b = 0; b < blocks; ++b) first_rank[b + 1] += first_rank[b];
  const std::size_t inside = first_rank[blocks];
  const std::size_t stride = inside <= limit ? 1 : (inside + limit - 1) / limit;
  std::vector<Vec3> kept((inside + stride - 1) / stride);
  if (indices) indices->assign(kept.size(), 0);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
    std::size_t rank = first_rank[b];
    for (std::size_t i = b * block; i < std::min(points.size(), (b + 1) * block); ++i) {
      if (!box.contains(points[i])) continue;
      if (rank % stride == 0) {
        kept[rank / stride] = points[i];
        if (indices) (*indices)[rank / stride] = i;
      }
      ++rank;
    }
  });
  return kept;
}

namespace {

// Applies `s` to every point, in parallel.
void apply_in_place(const Similarity& s, std::vector<Vec3>& points) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 1 << 14),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i < range.end(); ++i) {
                        points[i] = s.apply(points[i]);
                      }
                    });
}

}  // namespace

Vec3 camera_centre(const Mat4& camera_from_world) {
  return -camera_from_world.topLeftCorner<3, 3>().transpose() *
         camera_from_world.topRightCorner<3, 1>();
}

double rotation_angle_deg(const Eigen::Matrix3d& r) {
  const double c = std::clamp((r.trace() - 1) / 2, -1.0, 1.0);
  return std::acos(c) * 180 / M_PI;
}

ViewCamera view_camera(const run::ColmapCamera& cam, const Mat4& camera_from_world) {
  ViewCamera v;
  v.camera_from_world = camera_from_world;
  v.width = cam.width;
  v.height = cam.height;
  const auto& p = cam.params;
  if (cam.model == "SIMPLE_PINHOLE" || cam.model == "SIMPLE_RADIAL" || cam.model == "RADIAL") {
    v.fx = v.fy = p.at(0);
    v.cx = p.at(1);
    v.cy = p.at(2);
  } else {
    v.fx = p.at(0);
    v.fy = p.at(1);
    v.cx = p.at(2);
    v.cy = p.at(3);
  }
  return v;
}

namespace {

json similarity_json(const Similarity& s) {
  json m = json::array();
  const Mat4 x = s.matrix();
  for (int r = 0; r < 4; ++r) m.push_back({x(r, 0), x(r, 1), x(r, 2), x(r, 3)});
  return {{"scale", s.scale}, {"matrix", m}};
}

// The centroid of `points` and the median distance from it.
std::pair<Vec3, double> robust_radius(const std::vector<Vec3>& points) {
  Vec3 c = Vec3::Zero();
  for (const auto& p : points) c += p;
  c /= static_cast<double>(points.size());
  std::vector<double> r;
  for (const auto& p : points) r.push_back((p - c).norm());
  std::nth_element(r.begin(), r.begin() + r.size() / 2, r.end());
  return {c, r[r.size() / 2]};
}

// At most `limit` of `points`, evenly strided.
std::vector<Vec3> every_nth(const std::vector<Vec3>& points, std::size_t limit) {
  if (points.size() <= limit) return points;
  const std::size_t stride = (points.size() + limit - 1) / limit;
  std::vector<Vec3> kept;
  kept.reserve(limit);
  for (std::size_t i = 0; i < points.size(); i += stride) kept.push_back(points[i]);
  return kept;
}

// RANSAC seeds register_clouds() tries, and the camera-ring candidates it refines.
constexpr unsigned kRegistrationStarts = 4;
constexpr std::size_t kRingCandidates = 3;

// One alignment of one reconstruction; align() runs its steps.
class Aligner {
 public:
  Aligner(const EvalOptions& o, const SparseModel& model, const GroundTruth& truth,
          const Surface& surface, AlignMethod method, const std::vector<Vec3>* points)
      : o_(o),
        method_(method == AlignMethod::kAuto
                    ? (truth.poses.empty() ? AlignMethod::kRegistration : AlignMethod::kCameras)
                    : method),
        model_(model),
        truth_(truth),
        surface_(surface),
        diag_(surface.bounds().diagonal().norm()),
        crop_(object_crop(surface)),
        rec_points_(points ? *points : own_points_) {
    if (!points) {
      own_points_.reserve(model.points.size());
      for (const auto& p : model.points) own_points_.push_back(p.position);
    }
  }

  Alignment align() {
    const bool coarse = method_ == AlignMethod::kCameras        ? fit_camera_centres()
                        : method_ == AlignMethod::kRegistration ? register_clouds()
                                                                : keep_frame();
    if (!coarse) return std::move(a_);
    a_.points.resize(rec_points_.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rec_points_.size(), 1 << 14),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t i = range.begin(); i < range.end(); ++i) {
                          a_.points[i] = a_.transform.apply(rec_points_[i]);
                        }
                      });
    sample_visible_surface();
    if (o_.metrics.icp && method_ != AlignMethod::kNone) refine_with_icp();
    measure_fitness();
    a_.report["status"] = "ok";
    a_.report["reconstruction_to_ground_truth"] = similarity_json(a_.transform);
    a_.ok = true;
    return std::move(a_);
  }

 private:
  bool fail(std::string why) {
    a_.failure = std::move(why);
    return false;
  }

  // --no-align: the reconstruction is in the ground truth's frame already.
  bool keep_frame() {
    add_planned_views();
    a_.report = {{"method", "none: the reconstruction is in the scene's frame (--no-align)"}};
    return true;
  }

  void add_planned_views() {
    if (!truth_.camera) return;
    for (const auto& [name, pose] : truth_.poses) {
      a_.views.push_back(view_camera(*truth_.camera, pose));
    }
  }

  // The share of the aligned points near the object that lie on its surface: what tells a
  // reconstruction of this object from one of another.
  void measure_fitness() {
    std::vector<Vec3> inside;
    const std::size_t stride = std::max<std::size_t>(1, a_.points.size() / 200000);
    for (std::size_t i = 0; i < a_.points.size(); i += stride) {
      if (crop_.contains(a_.points[i])) inside.push_back(a_.points[i]);
    }
    a_.fitness_distance = std::max(0.01 * diag_, 3e-3 * o_.metrics.tau_mm);
    std::size_t close = 0;
    for (double d : surface_.signed_distance(inside)) close += std::abs(d) <= a_.fitness_distance;
    a_.fitness = inside.empty() ? 0 : static_cast<double>(close) / inside.size();
    a_.report["fitness"] = {
        {"value", a_.fitness},
        {"distance_mm", a_.fitness_distance * 1000},
        {"points_tested", inside.size()},
        {"definition",
         "share of the aligned points inside the object's bounds (grown by 5 %) within distance "
         "of the ground-truth surface"}};
  }

  // A run: the similarity that takes the reconstructed camera centres to the planned ones.
  bool fit_camera_centres() {
    // In the order of the names, so that RANSAC's samples do not depend on the file's order.
    std::map<std::string, const run::ColmapImage*> by_name;
    for (const auto& im : model_.images) by_name.emplace(im.name, &im);
    std::vector<Vec3> src, dst;
    for (const auto& [name, pose] : truth_.poses) {
      auto it = by_name.find(name);
      if (it == by_name.end()) continue;
      src.push_back(camera_centre(it->second->camera_from_world));
      dst.push_back(camera_centre(pose));
    }
    if (!truth_.camera) return fail("cannot align on cameras: the ground truth has no camera");
    add_planned_views();
    Vec3 centroid = Vec3::Zero();
    for (const auto& d : dst) centroid += d;
    if (!dst.empty()) centroid /= static_cast<double>(dst.size());
    double spread = 0;
    for (const auto& d : dst) spread += (d - centroid).squaredNorm();
    spread = dst.empty() ? 0 : std::sqrt(spread / static_cast<double>(dst.size()));
    auto robust = fit_similarity_ransac(src, dst, std::max(0.02 * spread, 1e-6), 2000, 1);
    if (!robust) {
      return fail(fmt::format(
          "cannot align: fewer than 3 registered images have a ground-truth pose ({} matched)",
          src.size()));
    }
    a_.transform = robust->transform;
    a_.report = {{"method", "Umeyama similarity in RANSAC on camera centres"},
                 {"cameras", src.size()},
                 {"inliers", robust->inliers.size()},
                 {"rms_camera_error_mm", robust->rms_inlier_error * 1000}};
    return true;
  }

  // Photos: no poses. Candidate similarities, each refined by ICP with scale and scored by its
  // distance to the surface; the closest wins. RANSAC on FPFH features of a partial cloud of a
  // near-symmetric object often settles on a wrong pose (seed by seed, 0 to 4 of 4 right on one
  // statue), so it starts from several seeds, and photos taken as the scene plans add one
  // candidate per turn of its camera ring.
  bool register_clouds() {
    std::vector<Vec3> samples, normals;
    surface_.sample(50000, 3, &samples, &normals);
    // 20k points tell the candidates apart and settle each similarity; the ICP after
    // registration refines the winner on up to 100k.
    const std::vector<Vec3> rec = every_nth(rec_points_, 20000);
    std::vector<std::pair<json, Similarity>> coarse = ransac_candidates(rec, samples);
    for (auto& candidate : ring_candidates(rec)) coarse.push_back(std::move(candidate));
    if (coarse.empty()) {
      return fail(
          "global registration found no alignment of the reconstruction to the mesh (RANSAC "
          "fitness 0: no feature correspondence agreed)");
    }
    std::optional<std::pair<Similarity, double>> best;
    json starts = json::array(), chosen;
    for (auto& [label, start] : coarse) {
      std::vector<Vec3> moved = rec;
      apply_in_place(start, moved);
      double fitness = 0;
      const Similarity candidate = refine_with_scale(moved, samples, &fitness) * start;
      const double distance = clipped_mean_distance(candidate, rec);
      label["icp_with_scale_fitness"] = fitness;
      label["clipped_mean_distance_mm"] = distance * 1000;
      if (!best || distance < best->second) {
        best = {candidate, distance};
        chosen = label;
      }
      starts.push_back(std::move(label));
    }
    a_.transform = best->first;
    a_.report = {{"method",
                  "candidates from FPFH + RANSAC (Open3D) with several seeds and from the "
                  "scene's camera ring, each refined by ICP with scale; the closest to the "
                  "surface"},
                 {"starts", starts},
                 {"chosen", chosen}};
    views_from_reconstruction();
    return true;
  }

  // Scale from the spread of the clouds, then FPFH + RANSAC from each seed.
  std::vector<std::pair<json, Similarity>> ransac_candidates(const std::vector<Vec3>& rec,
                                                             const std::vector<Vec3>& samples) {
    const auto [c_rec, r_rec] = robust_radius(rec);
    const auto [c_gt, r_gt] = robust_radius(samples);
    Similarity pre;
    pre.scale = r_gt / std::max(r_rec, 1e-12);
    pre.translation = c_gt - pre.scale * c_rec;
    std::vector<Vec3> moved = rec;
    apply_in_place(pre, moved);
    std::vector<std::pair<json, Similarity>> out;
    for (unsigned seed = 1; seed <= kRegistrationStarts; ++seed) {
      const auto global = global_registration(moved, samples, diag_ / 40, seed);
      if (global)
        out.push_back(
            {{{"from", "RANSAC"}, {"seed", seed}}, Similarity::from_matrix(*global) * pre});
    }
    return out;
  }

  // When every photo registered and the scene plans as many shots: the reconstructed camera
  // centres in file order fitted to the planned ones, the planned order turned by each shot
  // (where the turntable started is unknown) and reversed. The kRingCandidates closest to the
  // surface before ICP.
  std::vector<std::pair<json, Similarity>> ring_candidates(const std::vector<Vec3>& rec) const {
    const std::vector<Vec3>& planned = truth_.planned_eyes;
    std::vector<std::pair<json, Similarity>> out;
    if (planned.size() < 3 || planned.size() != model_.images.size()) return out;
    std::map<std::string, Vec3> by_name;
    for (const auto& im : model_.images) by_name[im.name] = camera_centre(im.camera_from_world);
    std::vector<Vec3> eyes;
    for (const auto& [name, eye] : by_name) eyes.push_back(eye);
    const int n = static_cast<int>(planned.size());
    std::vector<std::pair<double, std::pair<json, Similarity>>> scored;
    for (const int direction : {1, -1}) {
      for (int turn = 0; turn < n; ++turn) {
        std::vector<Vec3> dst;
        for (int i = 0; i < n; ++i) dst.push_back(planned[((turn + direction * i) % n + n) % n]);
        const auto fit = fit_similarity(eyes, dst);
        if (!fit) continue;
        const double distance = clipped_mean_distance(*fit, rec);
        json label = {{"from", "planned cameras"},
                      {"turn", turn},
                      {"reversed", direction < 0},
                      {"clipped_mean_distance_before_icp_mm", distance * 1000}};
        scored.push_back({distance, {std::move(label), *fit}});
      }
    }
    const std::size_t keep = std::min(scored.size(), kRingCandidates);
    std::partial_sort(scored.begin(), scored.begin() + keep, scored.end(),
                      [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t i = 0; i < keep; ++i) out.push_back(std::move(scored[i].second));
    return out;
  }

  // ICP with scale from coarse to fine correspondence distances: RANSAC's pose on voxels of 1/40
  // of the object is too rough for the fine step alone, which then settles a few mm off.
  Similarity refine_with_scale(std::vector<Vec3>& points, const std::vector<Vec3>& samples,
                               double* fitness) const {
    Similarity total;
    for (const double share : {1.0 / 10, 1.0 / 50, 1.0 / 200}) {
      const IcpResult step = icp_similarity(points, samples, share * diag_, 40);
      const Similarity s = Similarity::from_matrix(step.transform);
      apply_in_place(s, points);
      total = s * total;
      *fitness = step.fitness;
    }
    return total;
  }

  // The mean distance from the surface of `points` moved by `s`, each distance clipped at 2 % of
  // the object's diagonal and points outside the object's bounds counted at the clip.
  double clipped_mean_distance(const Similarity& s, const std::vector<Vec3>& points) const {
    const double clip = 0.02 * diag_;
    std::vector<Vec3> inside;
    const std::vector<Vec3> some = every_nth(points, 20000);
    for (const auto& p : some) {
      const Vec3 q = s.apply(p);
      if (crop_.contains(q)) inside.push_back(q);
    }
    double sum = clip * static_cast<double>(some.size() - inside.size());
    for (double d : surface_.signed_distance(inside)) sum += std::min(std::abs(d), clip);
    return some.empty() ? clip : sum / static_cast<double>(some.size());
  }

  // Without planned cameras, the reconstructed ones (aligned) see the ground truth:
  // camera_from_gt = camera_from_rec * rec_from_gt, made rigid (the scale goes into t).
  void views_from_reconstruction() {
    if (model_.cameras.empty()) return;
    const auto& cam = model_.cameras.front();
    const Similarity inv = a_.transform.inverse();
    for (const auto& im : model_.images) {
      Mat4 c = Mat4::Identity();
      c.topLeftCorner<3, 3>() = im.camera_from_world.topLeftCorner<3, 3>() * inv.rotation;
      c.topRightCorner<3, 1>() = im.camera_from_world.topLeftCorner<3, 3>() * inv.translation +
                                 im.camera_from_world.topRightCorner<3, 1>();
      c.topRightCorner<3, 1>() /= inv.scale;
      a_.views.push_back(view_camera(cam, c));
    }
  }

  void sample_visible_surface() {
    SurfaceSamples& s = a_.samples;
    surface_.sample(o_.metrics.ground_truth_samples, 7, &s.all, &s.all_normals);
    for (int i : surface_.visible(s.all, s.all_normals, a_.views)) {
      s.visible.push_back(s.all[i]);
      s.visible_normals.push_back(s.all_normals[i]);
    }
  }

  // Point-to-plane ICP of the points near the object onto the visible samples (all samples when
  // none is visible), applied when it found correspondences for 30 % of them.
  void refine_with_icp() {
    // ICP needs no more than 100k points near the object to settle a rigid transform.
    const std::vector<Vec3> inside = points_inside(a_.points, crop_, 100000);
    const SurfaceSamples& s = a_.samples;
    const bool none_visible = s.visible.empty();
    const std::vector<Vec3>& target = none_visible ? s.all : s.visible;
    const std::vector<Vec3>& target_n = none_visible ? s.all_normals : s.visible_normals;
    const IcpResult icp = icp_point_to_plane(inside, target, target_n, 0.01 * diag_, 50);
    json j = {{"method", "point-to-plane ICP (Open3D) on the visible ground-truth samples"},
              {"fitness", icp.fitness},
              {"inlier_rmse_mm", icp.inlier_rmse * 1000},
              {"translation_change_mm", icp.transform.topRightCorner<3, 1>().norm() * 1000},
              {"rotation_change_deg", rotation_angle_deg(icp.transform.topLeftCorner<3, 3>())}};
    if (icp.fitness >= 0.3) {
      const Similarity step = Similarity::from_matrix(icp.transform);
      a_.transform = step * a_.transform;
      apply_in_place(step, a_.points);
      j["applied"] = true;
    } else {
      j["applied"] = false;
      j["reason"] = "fewer than 30 % of the points found a correspondence";
    }
    a_.report["icp"] = j;
  }

  const EvalOptions& o_;
  const AlignMethod method_;
  const SparseModel& model_;
  const GroundTruth& truth_;
  const Surface& surface_;
  const double diag_;
  const Eigen::AlignedBox3d crop_;
  std::vector<Vec3> own_points_;  // model.points' positions, when no points were given
  const std::vector<Vec3>& rec_points_;
  Alignment a_;
};

}  // namespace

Alignment align_to_ground_truth(const EvalOptions& options, const SparseModel& model,
                                const GroundTruth& truth, const Surface& surface,
                                AlignMethod method, const std::vector<Vec3>* points) {
  return Aligner(options, model, truth, surface, method, points).align();
}

}  // namespace rigc::eval
