#include "eval/eval.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ostream>
#include <set>

#include "eval/align.h"
#include "eval/colmap.h"
#include "eval/geometry.h"
#include "eval/inputs.h"
#include "eval/measure.h"
#include "eval/photos.h"
#include "eval/reconstruction.h"
#include "eval/reference_check.h"
#include "eval/report.h"

namespace rigc::eval {

const std::vector<std::pair<std::string, Matcher>>& matcher_names() {
  static const std::vector<std::pair<std::string, Matcher>> names = {
      {"auto", Matcher::automatic},
      {"exhaustive", Matcher::exhaustive},
      {"sequential", Matcher::sequential},
      {"neighbours", Matcher::neighbours}};
  return names;
}

std::string matcher_name(Matcher matcher) {
  for (const auto& [name, value] : matcher_names()) {
    if (value == matcher) return name;
  }
  return "auto";
}

bool EvalOptions::check(std::string* error) const {
  auto refuse = [&](std::string why) {
    *error = std::move(why);
    return false;
  };
  if (run_dir.empty() == photos_dir.empty()) {
    return refuse("give a run folder or a folder of photos (one of them)");
  }
  if (sfm.colmap.empty()) return refuse("no COLMAP executable given");
  if (!(sfm.neighbour_angle_deg > 0 && sfm.neighbour_angle_deg <= 180)) {
    return refuse(fmt::format("the neighbour angle is {} deg; it must be in (0, 180]",
                              sfm.neighbour_angle_deg));
  }
  if (metrics.poisson_depth < 1 || metrics.poisson_depth > 16) {
    return refuse(
        fmt::format("the Poisson depth is {}; it must be in 1 .. 16", metrics.poisson_depth));
  }
  if (!(std::isfinite(metrics.tau_mm) && metrics.tau_mm > 0)) {
    return refuse(
        fmt::format("the F-score threshold is {} mm; it must be positive", metrics.tau_mm));
  }
  if (sfm.min_track_length < 2 || sfm.min_track_length > 1000) {
    return refuse(fmt::format("the minimum track length is {}; it must be in 2 .. 1000 (images)",
                              sfm.min_track_length));
  }
  if (metrics.ground_truth_samples < 1) {
    return refuse(
        fmt::format("{} ground-truth samples; at least 1 is needed", metrics.ground_truth_samples));
  }
  if (!(std::isfinite(photos.key_tolerance) && photos.key_tolerance > 0 &&
        photos.key_tolerance <= 1)) {
    return refuse(
        fmt::format("the key tolerance is {}; it must be in (0, 1] (a chromaticity distance)",
                    photos.key_tolerance));
  }
  if (photos_dir.empty() &&
      (!photos.masks_dir.empty() || !photos.camera.empty() || !photos.reference_cameras.empty())) {
    return refuse("--masks, --camera and --reference-cameras are for photos (--photos DIR)");
  }
  if (!(std::isfinite(metrics.color_range_mm) && metrics.color_range_mm >= 0)) {
    return refuse(fmt::format("the heat-map range is {} mm; it must be 0 (automatic) or positive",
                              metrics.color_range_mm));
  }
  if (imported.reconstruction.empty() && (!imported.cameras.empty() || !imported.align)) {
    return refuse("--cameras and --no-align go with --reconstruction FILE");
  }
  if (!imported.cameras.empty() && !imported.align)
    return refuse("give --cameras or --no-align, not both");
  if (imported.mesh_samples < 1000) {
    return refuse(fmt::format("{} mesh samples; at least 1000 are needed", imported.mesh_samples));
  }
  if (!(imported.min_fitness >= 0 && imported.min_fitness <= 1)) {
    return refuse(
        fmt::format("the minimum fitness is {}; it must be in 0 .. 1", imported.min_fitness));
  }
  return true;
}

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Photos of which fewer than half registered: the numbers describe a part of the object. An
// error unless --allow-partial.
bool too_few_registered(const EvalOptions& o, const EvalInputs& in, std::size_t registered,
                        std::ostream& log) {
  if (!in.photos || o.photos.allow_partial || 2 * registered >= in.images.names.size())
    return false;
  log << fmt::format(
      "rigc eval: error: only {} of the {} photos registered (fewer than half): the numbers "
      "above describe part of the object (see the causes above; --allow-partial accepts it)\n",
      registered, in.images.names.size());
  return true;
}

// Photos without a ground-truth mesh: the registration (and the reference cameras) is the
// result.
// (Eight parameters: the evaluation's state at this point, as evaluate() holds it.)
int finish_without_mesh(const EvalOptions& o, const EvalInputs& in, const ColmapRun& colmap,
                        EvalReport& report, EvalTimes& times, Clock::time_point t_start,
                        std::ostream& log, std::size_t registered) {
  times.total = seconds_since(t_start);
  report.add_timing(colmap, times);
  if (!report.write()) return 2;
  if (!o.quiet) report.print_written();
  return too_few_registered(o, in, registered, log) ? 2 : 0;
}

}  // namespace

int evaluate(const EvalOptions& o, std::ostream& log, EvalSummary* summary) {
  const auto t_start = Clock::now();
  EvalSummary local;
  EvalSummary& sum = summary ? *summary : local;
  std::string error;
  if (!o.check(&error)) {
    log << "rigc eval: error: " << error << "\n";
    return 1;
  }
  const auto in = gather_inputs(o, log, sum);
  if (!in) return 1;
  std::optional<PhotoSetup> photos;
  if (in->photos) {
    photos = prepare_photos(o, *in, log, &error);
    if (!photos) {
      log << "rigc eval: error: " << error << "\n";
      return 1;
    }
  }
  EvalReport report(*in, log, sum);
  if (photos) report.add_photos(*photos);
  if (!o.imported.reconstruction.empty())
    return evaluate_reconstruction(o, *in, report, log, sum, t_start);

  EvalTimes times;
  times.setup = seconds_since(t_start);
  const ColmapRun colmap = run_colmap(o, *in, log, photos ? &*photos : nullptr);
  report.add_colmap(colmap);
  const bool masked = colmap.prior.is_object() && colmap.prior.contains("masks");
  const bool mapped = std::any_of(colmap.steps.begin(), colmap.steps.end(), [](const auto& step) {
    return step.is_object() && step.value("name", "") == "mapper";
  });
  if (!colmap.ok && photos && mapped) {
    report.sections()["unregistered"] = report_unregistered(*in, &*photos, {}, masked, log);
    check_against_reference(o, *in, colmap, nullptr, report, log);
  }
  if (!colmap.ok) {
    return report.fail("reconstruction", colmap.failure, colmap.exit_code ? colmap.exit_code : 2);
  }
  const auto t_rigc = Clock::now();
  auto model = read_sparse_model(colmap.model_txt, &error);
  if (!model) return report.fail("reconstruction", error, 2);
  const std::size_t points_in_model = model->points.size();
  std::erase_if(model->points, [&](const Point3D& p) {
    return p.track_images.size() < static_cast<std::size_t>(o.sfm.min_track_length);
  });
  report.add_reconstruction(*model, colmap, points_in_model, o);
  std::set<std::string> registered;
  for (const auto& image : model->images) registered.insert(image.name);
  report.sections()["unregistered"] =
      report_unregistered(*in, photos ? &*photos : nullptr, registered, masked, log);
  check_against_reference(o, *in, colmap, &*model, report, log);
  if (!in->has_mesh()) {
    return finish_without_mesh(o, *in, colmap, report, times, t_start, log, registered.size());
  }
  if (model->points.size() < 3) {
    return report.fail("reconstruction", "the reconstruction has fewer than 3 points", 2);
  }

  const Surface surface(in->truth.positions, in->truth.triangles);
  const Alignment alignment = align_to_ground_truth(o, *model, in->truth, surface);
  if (!alignment.ok) return report.fail("alignment", alignment.failure, 2);
  report.sections()["alignment"] = alignment.report;
  const Measurements m =
      measure(o, *model, in->truth, surface, alignment, in->out, report.sections());
  sum.mean_mm = m.stats.mean;
  sum.std_mm = m.stats.stddev;
  sum.fscore = m.f.fscore;
  times.metrics = seconds_since(t_rigc);

  report.write_pictures(o, surface, alignment, m);
  sum.rigc_s = times.rigc = seconds_since(t_rigc);
  times.total = seconds_since(t_start);
  report.add_timing(colmap, times);
  if (!report.write()) return 2;
  if (!o.quiet) report.print_summary(o, colmap, m, times);
  return too_few_registered(o, *in, registered.size(), log) ? 2 : 0;
}

}  // namespace rigc::eval
