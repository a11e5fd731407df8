#include "eval/report.h"

#include <fmt/format.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>

#include "eval/metrics.h"
#include "io/files.h"

namespace rigc::eval {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// A camera that sees the whole ground truth from the front, above: the heat map's view when the
// reconstruction came without cameras.
ViewCamera overview_camera(const Surface& surface) {
  const Eigen::AlignedBox3d box = surface.bounds();
  const Vec3 centre = box.center();
  const double radius = std::max(box.diagonal().norm() / 2, 1e-9);
  constexpr double kHalfFovDeg = 20;
  const Vec3 eye = centre + Vec3(0.45, -0.8, 0.4).normalized() * radius * 1.15 /
                                std::sin(kHalfFovDeg * M_PI / 180);
  const Vec3 forward = (centre - eye).normalized();
  const Vec3 right = forward.cross(Vec3::UnitZ()).normalized();
  const Vec3 down = forward.cross(right);
  ViewCamera v;
  v.camera_from_world.topLeftCorner<3, 3>().row(0) = right.transpose();
  v.camera_from_world.topLeftCorner<3, 3>().row(1) = down.transpose();
  v.camera_from_world.topLeftCorner<3, 3>().row(2) = forward.transpose();
  v.camera_from_world.topRightCorner<3, 1>() = -v.camera_from_world.topLeftCorner<3, 3>() * eye;
  v.width = 1280;
  v.height = 960;
  v.fx = v.fy = (v.height / 2.0) / std::tan(kHalfFovDeg * M_PI / 180);
  v.cx = v.width / 2.0;
  v.cy = v.height / 2.0;
  return v;
}

}  // namespace

EvalReport::EvalReport(const EvalInputs& in, std::ostream& log, EvalSummary& summary)
    : out_(in.out), image_count_(in.images.names.size()), log_(log), summary_(summary) {
  report_["rigc_eval_version"] = 1;
  report_["input"] = {{"images_dir", in.images.dir.string()},
                      {"images", in.images.names.size()},
                      {"kind", in.photos ? "photos" : "run"},
                      {"ground_truth", in.truth.description},
                      {"ground_truth_triangles", in.truth.triangles.size()},
                      {"ground_truth_poses", !in.truth.poses.empty()}};
}

bool EvalReport::write() {
  std::string why;
  // Paths may hold any bytes; JSON holds UTF-8 only, so a stray byte becomes U+FFFD.
  if (!rigc::write_file_atomically(
          out_ / "eval.json", report_.dump(2, ' ', false, json::error_handler_t::replace) + "\n",
          &why)) {
    log_ << "rigc eval: error: " << why << "\n";
    return false;
  }
  summary_.report = report_;
  return true;
}

int EvalReport::fail(const std::string& section, const std::string& reason, int exit_code) {
  summary_.failure = reason;
  report_[section]["status"] = "failed";
  report_[section]["reason"] = reason;
  write();
  log_ << "rigc eval: error: " << reason << "\n";
  return exit_code;
}

void EvalReport::add_colmap(const ColmapRun& colmap) {
  report_["colmap"] = {{"steps", colmap.steps},
                       {"seconds", colmap.seconds},
                       {"matching", colmap.matching},
                       {"intrinsics_prior", colmap.prior}};
  summary_.colmap_s = colmap.seconds;
}

void EvalReport::add_photos(const PhotoSetup& photos) {
  json cameras = json::array();
  for (const auto& c : photos.cameras) cameras.push_back(c.to_json());
  report_["photos"] = {
      {"masks", photos.masks.report}, {"cameras", cameras}, {"capture_order", photos.order_basis}};
}

void EvalReport::add_reconstruction(const SparseModel& model, const ColmapRun& colmap,
                                    std::size_t points_in_model, const EvalOptions& options) {
  summary_.reconstructed = true;
  summary_.registered = static_cast<int>(model.images.size());
  summary_.points = static_cast<long>(model.points.size());
  report_["reconstruction"] = {
      {"status", "ok"},
      {"model", colmap.model_txt.string()},
      {"images", image_count_},
      {"registered_images", model.images.size()},
      {"points", model.points.size()},
      {"points_in_model", points_in_model},
      {"min_track_length", options.sfm.min_track_length},
      {"points_left_out",
       fmt::format("{} seen in fewer than {} images", points_in_model - model.points.size(),
                   options.sfm.min_track_length)},
      {"mean_track_length", model.mean_track_length()},
      {"mean_reprojection_error_px", model.mean_reprojection_error()}};
  if (options.quiet) return;
  log_ << fmt::format(
      "rigc eval: COLMAP: {}/{} images registered, {} points ({} seen in {}+ images, measured), "
      "track {:.2f}, reprojection {:.3f} px ({:.1f} s)\n",
      model.images.size(), image_count_, points_in_model, model.points.size(),
      options.sfm.min_track_length, model.mean_track_length(), model.mean_reprojection_error(),
      colmap.seconds);
}

void EvalReport::write_pictures(const EvalOptions& o, const Surface& surface,
                                const Alignment& alignment, const Measurements& m) {
  const std::vector<double>& d_mm = m.distance_mm;
  const DistanceStats& stats = m.point_stats;
  const double range =
      o.metrics.color_range_mm > 0 ? o.metrics.color_range_mm : std::max(1e-3, 3 * stats.rms);
  const ViewCamera view =
      alignment.views.empty() ? overview_camera(surface) : alignment.views.front();
  // Three independent files: the cloud's write overlaps the pictures' drawing.
  const fs::path cloud_ply = out_ / "cloud_signed_distance.ply";
  const fs::path histogram_png = out_ / "histogram.png";
  const fs::path heatmap_png = out_ / "heatmap.png";
  std::string cloud_why, histogram_why, heatmap_why;
  bool cloud_ok = false, histogram_ok = false, heatmap_ok = false;
  tbb::parallel_invoke(
      [&] { cloud_ok = write_colored_ply(cloud_ply, m.points, d_mm, range, &cloud_why); },
      [&] {
        histogram_ok = write_histogram_png(histogram_png, d_mm, range, stats, &histogram_why);
      },
      [&] {
        heatmap_ok = write_heatmap_png(heatmap_png, surface, view, m.points, d_mm, range, 1280,
                                       &heatmap_why);
      });
  json files;
  if (cloud_ok) files["cloud_ply"] = cloud_ply.string();
  if (histogram_ok) files["histogram_png"] = summary_.histogram_png = histogram_png.string();
  if (heatmap_ok) files["heatmap_png"] = summary_.heatmap_png = heatmap_png.string();
  for (const auto& [ok, why] :
       {std::pair{cloud_ok, &cloud_why}, std::pair{histogram_ok, &histogram_why},
        std::pair{heatmap_ok, &heatmap_why}}) {
    if (!ok) log_ << "rigc eval: warning: " << *why << "\n";
  }
  files["color_range_mm"] = range;
  report_["files"] = files;
}

void EvalReport::add_timing(const ColmapRun& colmap, const EvalTimes& t) {
  report_["timing_s"] = {{"colmap", colmap.seconds},     {"colmap_reused", colmap.reused},
                         {"rigc_ground_truth", t.setup}, {"rigc_alignment_and_metrics", t.metrics},
                         {"rigc_total", t.rigc},         {"total", t.total}};
}

void EvalReport::print_measurements(const EvalOptions& o, const Measurements& m) const {
  const DistanceStats& stats = m.stats;
  const std::string compared = report_.value("compared", "points");
  log_ << fmt::format(
      "rigc eval: signed distance {:.3f} ± {:.3f} mm (median {:.3f}, p90 |d| {:.3f}) over {} "
      "{}; F-score {:.3f} at {} mm (P {:.3f}, R {:.3f})\n",
      stats.mean, stats.stddev, stats.median, stats.p90_abs, stats.count,
      compared == "points"         ? "points"
      : compared == "mesh_samples" ? "mesh samples"
                                   : "Poisson-mesh samples",
      m.f.fscore, o.metrics.tau_mm, m.f.precision, m.f.recall);
}

void EvalReport::print_written() const {
  log_ << fmt::format("rigc eval: wrote {}\n", (out_ / "eval.json").string());
}

void EvalReport::print_summary(const EvalOptions& o, const ColmapRun& colmap, const Measurements& m,
                               const EvalTimes& t) const {
  print_measurements(o, m);
  // The time split: COLMAP's steps, then RigC's own parts.
  std::string colmap_split;
  for (const auto& step : colmap.steps) {
    if (!step.is_object()) continue;
    colmap_split += fmt::format(", {} {:.1f}", step.value("name", "?"), step.value("seconds", 0.0));
  }
  if (colmap.matching.contains("pairs")) {
    colmap_split += fmt::format("; {} matching, {} pairs", colmap.matching.value("matcher", "?"),
                                colmap.matching["pairs"].dump());
  }
  log_ << fmt::format(
      "rigc eval: {:.1f} s in all: COLMAP {:.1f} s{}{}, RigC {:.1f} s (ground truth {:.1f}, "
      "alignment and metrics {:.1f}, files {:.1f})\n",
      t.total, colmap.seconds, colmap.reused ? " (reused: the earlier run's)" : "",
      colmap_split.empty() ? "" : " (" + colmap_split.substr(2) + ")", t.setup + t.rigc, t.setup,
      t.metrics, t.rigc - t.metrics);
  print_written();
}

}  // namespace rigc::eval
