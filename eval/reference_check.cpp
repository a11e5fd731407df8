#include "eval/reference_check.h"

#include <fmt/format.h>

#include <cmath>

#include "eval/known_poses.h"
#include "eval/pose_accuracy.h"

namespace rigc::eval {

using nlohmann::json;

namespace {

double median_of(const json& stats) {
  return stats.is_object() ? stats.value("median", NAN) : NAN;
}

void report_pose_accuracy(const EvalOptions& o, const EvalInputs& in, const SparseModel& model,
                          EvalReport& report, std::ostream& log) {
  std::map<std::string, Mat4> estimated;
  std::map<std::string, run::ColmapCamera> intrinsics;
  for (const auto& im : model.images) {
    estimated[im.name] = im.camera_from_world;
    if (const run::ColmapCamera* c = model.camera_of(im)) intrinsics[im.name] = *c;
  }
  const PoseAccuracy acc =
      measure_pose_accuracy(in.images.names, in.reference, estimated, intrinsics);
  json& section = report.sections()["cameras"];
  if (!acc.ok) {
    section = {
        {"reference", in.reference_description}, {"status", "failed"}, {"reason", acc.failure}};
    log << "rigc eval: warning: " << acc.failure << "\n";
    return;
  }
  section = acc.report;
  section["reference"] = in.reference_description;
  if (o.quiet) return;
  log << fmt::format(
      "rigc eval: against {}: rotation error median {:.3f} deg, centre error median {:.2f} mm "
      "({:.2f} % of the distance), |focal length error| median {:.2f} %; relative-pose AUC at "
      "1/2/5/10 deg {:.1f}/{:.1f}/{:.1f}/{:.1f} %\n",
      in.reference_description, median_of(section["rotation_error_deg"]),
      median_of(section["centre_error_mm"]), median_of(section["centre_error_percent_of_distance"]),
      median_of(section["abs_focal_length_error_percent"]), acc.auc[0], acc.auc[1], acc.auc[2],
      acc.auc[3]);
}

// Too few registered: the points at the reference poses, as the "known_poses" section.
void report_known_poses(const EvalOptions& o, const EvalInputs& in, const ColmapRun& colmap,
                        std::size_t registered, EvalReport& report, std::ostream& log) {
  const std::string why = fmt::format(
      "SfM registered {} of the {} photos (fewer than half): the points are triangulated from "
      "the photos' matches with the cameras held at the reference (COLMAP point_triangulator)",
      registered, in.images.names.size());
  if (!o.quiet) log << "rigc eval: " << why << "\n";
  const ColmapRun known = triangulate_known_poses(o, in, colmap, log);
  json& section = report.sections()["known_poses"];
  section = {{"why", why}, {"steps", known.steps}, {"seconds", known.seconds}};
  std::string error;
  const auto model = known.ok ? read_sparse_model(known.model_txt, &error) : std::nullopt;
  if (!model) {
    section["status"] = "failed";
    section["reason"] = known.ok ? error : known.failure;
    log << "rigc eval: warning: triangulating at the reference poses failed: "
        << section["reason"].get<std::string>() << "\n";
    return;
  }
  section.update({{"status", "ok"},
                  {"model", known.model_txt.string()},
                  {"points", model->points.size()},
                  {"mean_track_length", model->mean_track_length()},
                  {"mean_reprojection_error_px", model->mean_reprojection_error()}});
  if (o.quiet) return;
  log << fmt::format(
      "rigc eval: at the reference poses: {} points, track {:.2f}, reprojection {:.3f} px "
      "({:.1f} s; eval.json's known_poses)\n",
      model->points.size(), model->mean_track_length(), model->mean_reprojection_error(),
      known.seconds);
}

}  // namespace

void check_against_reference(const EvalOptions& o, const EvalInputs& in, const ColmapRun& colmap,
                             const SparseModel* model, EvalReport& report, std::ostream& log) {
  if (in.reference.empty()) return;
  if (model) report_pose_accuracy(o, in, *model, report, log);
  const std::size_t registered = model ? model->images.size() : 0;
  const bool matched = std::filesystem::exists(in.out / "colmap" / "database.db");
  if (2 * registered < in.images.names.size() && matched) {
    report_known_poses(o, in, colmap, registered, report, log);
  }
}

}  // namespace rigc::eval
