// `rigc plan`: the fewest shots, from the poses the studio allows, that reach a coverage target.
#include <fmt/format.h>

#include <filesystem>
#include <iostream>

#include "cli/commands.h"
#include "cli/options.h"
#include "cli/verbs.h"
#include "compiler/units.h"
#include "io/atomic_file.h"
#include "io/input_files.h"
#include "plan/plan_scene.h"
#include "plan/report.h"
#include "run/scene_inputs.h"

namespace rigc::cli {
namespace {

namespace fs = std::filesystem;

// A comma-separated list of quantities of one kind, each within [lowest, highest] (SI).
std::optional<std::vector<double>> parse_list(const std::string& text, QuantityKind kind,
                                              double lowest, double highest, std::string* error) {
  std::vector<double> values;
  std::stringstream items(text);
  for (std::string item; std::getline(items, item, ',');) {
    const QuantityParse parsed = parse_quantity(item, kind);
    if (!parsed.value) {
      *error = fmt::format("'{}': {}", item, parsed.error);
      return std::nullopt;
    }
    if (!(*parsed.value >= lowest && *parsed.value <= highest)) {
      *error = fmt::format("'{}' is outside {}..{}", item, format_quantity(lowest, kind),
                           format_quantity(highest, kind));
      return std::nullopt;
    }
    values.push_back(*parsed.value);
  }
  if (values.empty() || values.size() > 36) {
    *error = fmt::format("'{}' is not a list of 1 to 36 values", text);
    return std::nullopt;
  }
  return values;
}

struct PlanArguments {
  std::string target = "95%", rings, distances, azimuth_step = "10deg", max_step = "30deg";
  bool next = false;
};

// The request from the options; false after printing why it is not one.
bool make_request(const PlanArguments& args, plan::PlanRequest& request) {
  std::string error;
  const auto target = parse_target(args.target);
  if (!target) error = fmt::format("--target '{}' is not a share like 95% or 0.95", args.target);
  if (target) request.target = *target;
  if (error.empty() && !args.rings.empty()) {
    const auto rings =
        parse_list(args.rings, QuantityKind::kAngle, -60 * kDegree, 85 * kDegree, &error);
    if (rings) request.candidates.ring_elevations_rad = *rings;
    if (!rings) error = "--rings " + error;
  }
  if (error.empty() && !args.distances.empty()) {
    const auto distances = parse_list(args.distances, QuantityKind::kLength, 0.05, 100, &error);
    if (distances) request.candidates.distances_m = *distances;
    if (!distances) error = "--distances " + error;
  }
  if (error.empty()) {
    const QuantityParse step = parse_quantity(args.azimuth_step, QuantityKind::kAngle);
    if (!step.value || !(*step.value >= 1 * kDegree && *step.value <= 180 * kDegree)) {
      error =
          fmt::format("--azimuth-step '{}' is not an angle within 1deg..180deg", args.azimuth_step);
    } else {
      request.candidates.azimuth_step_rad = *step.value;
    }
  }
  if (error.empty()) {
    const QuantityParse step = parse_quantity(args.max_step, QuantityKind::kAngle);
    if (!step.value || !(*step.value >= 5 * kDegree && *step.value <= 180 * kDegree)) {
      error = fmt::format("--max-step '{}' is not an angle within 5deg..180deg", args.max_step);
    } else {
      request.max_step_rad = *step.value;
    }
  }
  if (!error.empty()) std::cerr << "rigc: error: " << error << '\n';
  return error.empty();
}

// Beside the scene by default, so that its relative mesh paths still hold; never the scene itself.
bool choose_output(plan::PlanRequest& request) {
  const fs::path scene(request.scene_path);
  if (request.output_path.empty()) {
    request.output_path = (scene.parent_path() / (scene.stem().string() + "-plan.yaml")).string();
  }
  std::error_code ec;
  if (fs::equivalent(scene, request.output_path, ec)) {
    std::cerr << fmt::format("rigc: error: -o {} is the scene itself; plan into another file\n",
                             request.output_path);
    return false;
  }
  const fs::path folder = fs::path(request.output_path).parent_path();
  if (!folder.empty() && !fs::is_directory(folder, ec)) {
    std::cerr << fmt::format("rigc: error: the folder of -o {} does not exist\n",
                             request.output_path);
    return false;
  }
  return true;
}

}  // namespace

// "95%" or "0.95": a share in (0, 1].
std::optional<double> parse_target(const std::string& text) {
  const bool percent = text.ends_with('%');
  const auto quantity =
      parse_quantity(percent ? text.substr(0, text.size() - 1) : text, QuantityKind::kNumber);
  if (!quantity.value) return std::nullopt;
  const double share = percent ? *quantity.value / 100 : *quantity.value;
  if (!(share > 0 && share <= 1)) return std::nullopt;
  return share;
}

int run_plan_command(std::vector<std::string> args) {
  CLI::App app{
      "Plan the fewest shots that reach a share of reconstructable surface, and write "
      "the scene with them."};
  app.footer("\nExample:\n  rigc plan scenes/paper-turntable.yaml --target 90%");
  plan::PlanRequest request;
  PlanArguments arguments;
  app.add_option("scene", request.scene_path, "scene file (.yaml)")->required();
  app.add_option("-o,--output", request.output_path,
                 "planned scene file (default: SCENE-plan.yaml beside the scene)");
  app.add_option("--target", arguments.target, "share of the surface to make reconstructable")
      ->capture_default_str();
  app.add_option("--rings", arguments.rings,
                 "elevations of extra camera rings, as 0,20deg,40 (default 0,20,40,60,80)");
  app.add_option("--distances", arguments.distances,
                 "distances of the extra rings from the object, as 90cm,1.2m (default: the "
                 "scene's)");
  app.add_option("--azimuth-step", arguments.azimuth_step,
                 "turntable step (or orbit azimuth step) between candidate poses")
      ->capture_default_str();
  app.add_option("--max-shots", request.max_shots, "most shots in the plan (0: no limit)")
      ->check(CLI::Range(0, 5000));
  app.add_option("--max-step", arguments.max_step,
                 "widest angle between neighbouring shots, seen from the object, that still "
                 "chains them")
      ->capture_default_str();
  app.add_flag("--keep-shots", request.keep_scene_shots,
               "keep the scene's shots and plan the ones to add");
  app.add_flag("--next", arguments.next,
               "only the one shot that adds most to the scene's own (as --keep-shots)");
  app.add_flag("--turntable-only", request.candidates.turntable_only,
               "only the scene's own camera stations; the plan picks turntable angles");
  app.add_option("--visibility-scale", request.visibility_scale,
                 "resolution of the visibility buffers relative to the sensor (0: ~1400 px)")
      ->check(finite_number_where([](double v) { return v == 0 || (v >= 0.01 && v <= 1); },
                                  "is neither 0 (automatic) nor within 0.01..1", ""));
  if (auto code = parse_options(app, args)) return *code;
  if (!make_request(arguments, request) || !choose_output(request)) return kExitUserError;
  if (arguments.next) {
    // The best shot to add, whatever the scene reaches already.
    request.keep_scene_shots = true;
    request.target = 1;
    request.max_shots = 0;
    request.next_shot_only = true;
  }

  DiagnosticEngine diag;
  std::string error;
  protect_input_file(request.scene_path, "the scene file");
  const auto outcome = plan::plan_scene(request, diag, &error);
  if (!outcome) {
    if (!error.empty()) std::cerr << "rigc: error: " << error << '\n';
    return kExitUserError;
  }
  run::protect_scene_inputs(request.scene_path, outcome->scene);
  plan::print_plan_report(*outcome, std::cout);
  if (!write_file_atomically(request.output_path, outcome->planned_text, &error)) {
    std::cerr << "rigc: error: " << error << '\n';
    return kExitUserError;
  }
  std::cout << fmt::format("planned scene: {}\n", request.output_path);
  return outcome->plan.target_reached || arguments.next ? kExitOk : kExitUserError;
}

}  // namespace rigc::cli
