#include "eval/measure.h"

#include <algorithm>
#include <map>
#include <string>

#include "assets/mesh_io.h"

namespace rigc::eval {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

json stats_json(const DistanceStats& s) {
  return {{"count", s.count},   {"mean", s.mean},       {"std", s.stddev},
          {"median", s.median}, {"p90_abs", s.p90_abs}, {"mean_abs", s.mean_abs},
          {"rms", s.rms},       {"min", s.min},         {"max", s.max}};
}

std::vector<double> signed_distance_mm(const Surface& surface, const std::vector<Vec3>& points) {
  std::vector<double> d_mm = surface.signed_distance(points);
  for (double& d : d_mm) d *= 1000;
  return d_mm;
}

// The Poisson mesh's samples and their distances, which replace the points' in the precision and
// the recall when --poisson meshed them.
struct PoissonSamples {
  std::vector<double> distance_mm;
  std::vector<Vec3> cloud;
};

// One measurement of an aligned reconstruction; run() takes its steps.
class Measurer {
 public:
  Measurer(const EvalOptions& o, const SparseModel& model, const GroundTruth& truth,
           const Surface& surface, const Alignment& a, const fs::path& out, json& report,
           const Surface* reconstructed_mesh)
      : o_(o),
        model_(model),
        truth_(truth),
        surface_(surface),
        a_(a),
        out_(out),
        report_(report),
        reconstructed_mesh_(reconstructed_mesh) {}

  Measurements run() {
    keep_points_near_object();
    m_.distance_mm = signed_distance_mm(surface_, m_.points);
    m_.stats = distance_stats(m_.distance_mm);
    json distances = stats_json(m_.stats);
    distances["cropped_points"] = a_.points.size() - m_.points.size();
    distances["crop"] = "ground-truth bounds grown by 5 % of their diagonal on every side";
    report_["compared"] = reconstructed_mesh_ ? "mesh_samples" : "points";
    report_["signed_distance_mm"] = distances;
    report_["signed_distance_mm"]["convention"] =
        "nearest ground-truth triangle, positive on its normal's side (outside)";
    m_.point_stats = m_.stats;
    // Poisson needs the points' observers: COLMAP's points have them, a file's have not.
    PoissonSamples poisson;
    if (o_.metrics.poisson && view_points_.size() == m_.points.size() && !m_.points.empty()) {
      compare_poisson_mesh(poisson);
    }
    if (poisson.cloud.empty()) {
      score(m_.distance_mm, m_.points);
    } else {
      score(poisson.distance_mm, poisson.cloud);
    }
    if (!truth_.poses.empty() && !model_.images.empty()) camera_errors();
    return std::move(m_);
  }

 private:
  // The points inside object_crop, and with --poisson for each the mean centre of the cameras
  // observing it (Poisson orients its normals towards them).
  void keep_points_near_object() {
    const bool tracks = o_.metrics.poisson && model_.points.size() == a_.points.size();
    std::vector<std::size_t> kept;
    m_.points = points_inside(a_.points, object_crop(surface_),
                              std::numeric_limits<std::size_t>::max(), tracks ? &kept : nullptr);
    for (std::size_t i : kept) view_points_.push_back(mean_observer(model_.points[i]));
  }

  // Where a point was seen from: the mean centre of its track's cameras (aligned), or above the
  // object when it has none.
  Vec3 mean_observer(const Point3D& point) {
    if (centre_gt_.empty()) {
      for (const auto& im : model_.images) {
        centre_gt_[im.image_id] = a_.transform.apply(camera_centre(im.camera_from_world));
      }
    }
    Vec3 v = Vec3::Zero();
    int n = 0;
    for (int id : point.track_images) {
      auto it = centre_gt_.find(id);
      if (it != centre_gt_.end()) {
        v += it->second;
        ++n;
      }
    }
    const Eigen::AlignedBox3d box = surface_.bounds();
    return n ? Vec3(v / n) : Vec3(box.center() + Vec3(0, 0, box.diagonal().norm()));
  }

  // --poisson: a screened Poisson mesh of the points, measured by its surface samples.
  void compare_poisson_mesh(PoissonSamples& samples) {
    std::string why;
    auto mesh = poisson_mesh(m_.points, view_points_, o_.metrics.poisson_depth, &why);
    if (!mesh) {
      report_["poisson_mesh"] = {{"status", "failed"}, {"reason", why}};
      return;
    }
    Surface rec_surface(mesh->positions, mesh->triangles);
    std::vector<Vec3> mesh_samples, mesh_normals;
    rec_surface.sample(std::max<int>(100000, static_cast<int>(m_.points.size())), 11, &mesh_samples,
                       &mesh_normals);
    std::vector<double> dm = signed_distance_mm(surface_, mesh_samples);
    const DistanceStats ms = distance_stats(dm);
    report_["compared"] = "poisson_mesh";
    report_["poisson_mesh"] = {{"depth", o_.metrics.poisson_depth},
                               {"triangles", mesh->triangles.size()},
                               {"samples", mesh_samples.size()},
                               {"signed_distance_mm", stats_json(ms)}};
    ir::Mesh m;
    m.positions = mesh->positions;
    m.triangles = mesh->triangles;
    if (write_ply((out_ / "poisson_mesh.ply").string(), m, &why)) {
      report_["poisson_mesh"]["file"] = (out_ / "poisson_mesh.ply").string();
    }
    samples = {std::move(dm), std::move(mesh_samples)};
    m_.stats = ms;
  }

  // Distances (mm) of the ground-truth samples `reference` to the reconstructed mesh: in its own
  // frame, scaled back.
  std::vector<double> distances_to_reconstructed_mesh(const std::vector<Vec3>& reference) const {
    const Similarity inv = a_.transform.inverse();
    std::vector<Vec3> in_mesh_frame;
    in_mesh_frame.reserve(reference.size());
    for (const auto& p : reference) in_mesh_frame.push_back(inv.apply(p));
    std::vector<double> d = reconstructed_mesh_->signed_distance(in_mesh_frame);
    for (auto& x : d) x = std::abs(x) * a_.transform.scale * 1000;
    return d;
  }

  // Precision from `distance_mm` (of `cloud` to the ground truth), recall from the ground-truth
  // samples' distances to `cloud`.
  void score(const std::vector<double>& distance_mm, const std::vector<Vec3>& cloud) {
    const SurfaceSamples& s = a_.samples;
    const bool all = s.visible.empty();
    const std::vector<Vec3>& reference = all ? s.all : s.visible;
    std::vector<double> truth_to_rec;
    if (reconstructed_mesh_ && report_["compared"] == "mesh_samples") {
      truth_to_rec = distances_to_reconstructed_mesh(reference);
    } else {
      truth_to_rec = nearest_distances(reference, cloud);
      for (auto& d : truth_to_rec) d *= 1000;
    }
    m_.f = f_score(distance_mm, truth_to_rec, o_.metrics.tau_mm);
    report_["fscore"] = {
        {"tau_mm", m_.f.tau},
        {"precision", m_.f.precision},
        {"recall", m_.f.recall},
        {"fscore", m_.f.fscore},
        {"ground_truth_samples", s.all.size()},
        {"visible_ground_truth_samples", s.visible.size()},
        {"recall_reference", all ? "all ground-truth samples (no camera to tell what was seen)"
                                 : "the ground-truth samples a camera sees"},
        {"definition",
         "Tanks and Temples: precision = share of the compared geometry within tau of the "
         "ground-truth mesh; recall = share of visible ground-truth samples within tau of it"}};
  }

  // The reconstructed cameras, aligned, against the planned ones.
  void camera_errors() {
    std::vector<double> pos_mm, rot_deg;
    const Similarity& align = a_.transform;
    const Similarity inv = align.inverse();
    for (const auto& im : model_.images) {
      auto it = truth_.poses.find(im.name);
      if (it == truth_.poses.end()) continue;
      pos_mm.push_back(
          1000 *
          (align.apply(camera_centre(im.camera_from_world)) - camera_centre(it->second)).norm());
      const Eigen::Matrix3d r_rec = im.camera_from_world.topLeftCorner<3, 3>() * inv.rotation;
      rot_deg.push_back(rotation_angle_deg(it->second.topLeftCorner<3, 3>() * r_rec.transpose()));
    }
    const DistanceStats ps = distance_stats(pos_mm), rs = distance_stats(rot_deg);
    report_["cameras"] = {
        {"compared", pos_mm.size()},
        {"position_error_mm", {{"mean", ps.mean}, {"median", ps.median}, {"max", ps.max}}},
        {"rotation_error_deg", {{"mean", rs.mean}, {"median", rs.median}, {"max", rs.max}}}};
  }

  const EvalOptions& o_;
  const SparseModel& model_;
  const GroundTruth& truth_;
  const Surface& surface_;
  const Alignment& a_;
  const fs::path& out_;
  json& report_;
  const Surface* reconstructed_mesh_;
  std::vector<Vec3> view_points_;  // per kept point: where it was seen from (--poisson)
  std::map<int, Vec3> centre_gt_;  // camera centres by image id, aligned
  Measurements m_;
};

}  // namespace

Measurements measure(const EvalOptions& options, const SparseModel& model, const GroundTruth& truth,
                     const Surface& surface, const Alignment& alignment, const fs::path& out,
                     json& report, const Surface* reconstructed_mesh) {
  return Measurer(options, model, truth, surface, alignment, out, report, reconstructed_mesh).run();
}

}  // namespace rigc::eval
