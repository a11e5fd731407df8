#include "plan/plan_scene.h"

#include <fmt/format.h>

#include <chrono>
#include <filesystem>

#include "compiler/check.h"
#include "compiler/frontend.h"
#include "compiler/limits.h"
#include "compiler/scene_text.h"
#include "scene/studio_scene.h"

namespace rigc::plan {
namespace {

namespace fs = std::filesystem;

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string folder_of(const std::string& path) {
  const std::string folder = fs::path(path).parent_path().string();
  return folder.empty() ? std::string(".") : folder;
}

// The checked description of a scene that compiled: the stations the candidates start from.
std::optional<spec::SceneSpec> scene_spec(const std::string& text, const std::string& path) {
  DiagnosticEngine quiet;
  quiet.set_handler([](const Diagnostic&, const std::string&) {});
  const auto root = parse_yaml(text, path, quiet);
  if (!root) return std::nullopt;
  return check_scene(*root, path, folder_of(path), quiet);
}

// The first error of a compile, rendered, for messages about text RigC wrote itself.
std::string first_error(const DiagnosticEngine& diag) {
  for (const Diagnostic& d : diag.diagnostics()) {
    if (d.severity == Severity::kError) return diag.render(d);
  }
  return "no diagnostic";
}

PlanProblem make_problem(const CandidateSet& set, int kept, const ir::Scene& candidate_scene,
                         const analysis::CoverageResult& coverage) {
  PlanProblem problem;
  problem.coverage = &coverage;
  problem.kept = kept;
  problem.station.assign(kept, -1);
  problem.angle_deg.assign(kept, 0);
  for (const Candidate& candidate : set.candidates) {
    problem.station.push_back(candidate.station);
    problem.angle_deg.push_back(candidate.angle_deg);
  }
  for (const Station& station : set.stations) {
    // Poses come last: after the rings.
    problem.station_elevation_rad.push_back(
        station.kind == StationKind::kPose ? 1e9 : station.elevation_rad);
  }
  problem.cos_min_triangulation = std::cos(candidate_scene.coverage.min_triangulation_angle_rad);
  problem.object_center =
      (candidate_scene.object.bounds_min_object + candidate_scene.object.bounds_max_object) / 2;
  return problem;
}

// Every candidate compiled as one scene, and its coverage with sights.
bool analyse_candidates(const std::string& text, const PlanRequest& request, PlanOutcome& outcome,
                        std::string* error) {
  std::string replace_error;
  const auto candidate_text = replace_section(
      text, "shots", shots_yaml(outcome.candidates, all_candidates(outcome.candidates), false),
      &replace_error);
  if (!candidate_text) {
    *error = replace_error;
    return false;
  }
  DiagnosticEngine diag;
  diag.set_handler([](const Diagnostic&, const std::string&) {});
  auto candidate_scene = compile_scene_text(*candidate_text, request.scene_path + " (candidates)",
                                            folder_of(request.scene_path), diag);
  if (!candidate_scene || candidate_scene->shots.size() != outcome.candidates.candidates.size()) {
    *error = "the candidate poses do not compile: " + first_error(diag);
    return false;
  }
  if (request.keep_scene_shots) {
    outcome.kept = static_cast<int>(outcome.scene.shots.size());
    candidate_scene->shots.insert(candidate_scene->shots.begin(), outcome.scene.shots.begin(),
                                  outcome.scene.shots.end());
    for (size_t i = 0; i < candidate_scene->shots.size(); ++i) {
      candidate_scene->shots[i].index = static_cast<int>(i);
    }
  }
  const scene::StudioScene studio = scene::prepare_studio_scene(*candidate_scene);
  analysis::CoverageOptions options;
  options.visibility_scale = request.visibility_scale;
  options.keep_sights = true;
  outcome.candidate_coverage = analysis::analyse_coverage(*candidate_scene, studio, options);
  outcome.problem =
      make_problem(outcome.candidates, outcome.kept, *candidate_scene, outcome.candidate_coverage);
  outcome.candidate_shots = candidate_scene->shots;
  return true;
}

}  // namespace

std::unique_ptr<PlanOutcome> plan_scene(const PlanRequest& request, DiagnosticEngine& diag,
                                        std::string* error) {
  // The file is read once: this text is compiled, and edited into the candidates and the plan.
  const auto text = request.scene_text.empty() ? read_scene_file(request.scene_path, diag)
                                               : std::optional<std::string>(request.scene_text);
  if (!text) return nullptr;
  auto scene = compile_scene_text(*text, request.scene_path, folder_of(request.scene_path), diag);
  if (!scene) return nullptr;
  // The scene compiled, so its checked description exists.
  const auto spec = scene_spec(*text, request.scene_path);
  if (!spec) {
    *error = fmt::format("{} compiled but does not check", request.scene_path);
    return nullptr;
  }
  // The plan is written at the output path, so the scene's relative files must resolve from
  // there: said before the minutes of analysis, not after. Beside the scene they do (it compiled).
  DiagnosticEngine at_output;
  at_output.set_handler([](const Diagnostic&, const std::string&) {});
  if (folder_of(request.output_path) != folder_of(request.scene_path) &&
      !compile_scene_text(*text, request.output_path, folder_of(request.output_path), at_output)) {
    *error = fmt::format(
        "the scene would not compile at {}: {} (write the plan beside the scene, the default, "
        "or give the scene's files absolute paths)",
        request.output_path, first_error(at_output));
    return nullptr;
  }
  auto outcome = std::make_unique<PlanOutcome>();
  outcome->scene = std::move(*scene);
  const auto start = std::chrono::steady_clock::now();
  {
    const scene::StudioScene studio = scene::prepare_studio_scene(outcome->scene);
    analysis::CoverageOptions options;
    options.visibility_scale = request.visibility_scale;
    outcome->coverage = analysis::analyse_coverage(outcome->scene, studio, options);
  }
  outcome->candidates = make_candidates(*spec, outcome->scene, request.candidates);
  const size_t count = outcome->candidates.candidates.size();
  if (count == 0 || count > static_cast<size_t>(limits::kMostShots)) {
    *error = fmt::format(
        "{} candidate poses; a plan needs 1 to {} (change --rings, --distances "
        "or --azimuth-step)",
        count, limits::kMostShots);
    return nullptr;
  }
  if (!analyse_candidates(*text, request, *outcome, error)) return nullptr;
  outcome->candidate_seconds = seconds_since(start);

  const auto search_start = std::chrono::steady_clock::now();
  outcome->options.target = request.target;
  outcome->options.max_shots = request.next_shot_only ? outcome->kept + 1 : request.max_shots;
  outcome->next_shot_only = request.next_shot_only;
  // The next shot adds the most reconstructable area; first views only break ties.
  if (request.next_shot_only) outcome->options.first_view_weight = 1e-6;
  outcome->options.min_overlap = outcome->scene.coverage.min_overlap;
  outcome->options.max_step_rad = request.max_step_rad;
  outcome->plan = plan_capture(outcome->problem, outcome->options);
  outcome->search_seconds = seconds_since(search_start);

  std::string replace_error;
  const auto planned =
      request.keep_scene_shots
          ? append_to_section(*text, "shots", planned_shots_text(*outcome), &replace_error)
          : replace_section(*text, "shots", planned_shots_text(*outcome), &replace_error);
  if (!planned) {
    *error = replace_error;
    return nullptr;
  }
  outcome->planned_text = *planned;
  // The planned file must compile where it will be written (relative mesh paths).
  DiagnosticEngine check;
  check.set_handler([](const Diagnostic&, const std::string&) {});
  if (!compile_scene_text(outcome->planned_text, request.output_path,
                          folder_of(request.output_path), check)) {
    *error = fmt::format("the planned scene would not compile at {}: {}", request.output_path,
                         first_error(check));
    return nullptr;
  }
  return outcome;
}

const Candidate* planned_candidate(const PlanOutcome& outcome, const PlannedShot& shot) {
  if (shot.candidate < outcome.kept) return nullptr;
  return &outcome.candidates.candidates[shot.candidate - outcome.kept];
}

std::string planned_shots_text(const PlanOutcome& outcome) {
  std::vector<int> added;
  for (const PlannedShot& shot : outcome.plan.shots) {
    if (shot.candidate >= outcome.kept) added.push_back(shot.candidate - outcome.kept);
  }
  const std::string figures = fmt::format(
      "{} shots make {:.1f} % of the surface reconstructable (target {:.1f} %)",
      outcome.plan.shots.size(), outcome.plan.reconstructable * 100, outcome.options.target * 100);
  const std::string entries = shots_yaml(outcome.candidates, added, true);
  if (outcome.next_shot_only) {
    const double gain = outcome.plan.shots.empty() ? 0 : outcome.plan.shots.back().gain;
    return fmt::format(
               "  # Suggested by `rigc plan --next`: adds {:.1f} %; {} shots make {:.1f} % "
               "reconstructable.\n",
               gain * 100, outcome.plan.shots.size(), outcome.plan.reconstructable * 100) +
           entries.substr(entries.find('\n') + 1);
  }
  if (outcome.kept > 0) {
    return fmt::format("  # Added by `rigc plan`: with these, {}.\n", figures) +
           entries.substr(entries.find('\n') + 1);
  }
  return fmt::format("# Planned by `rigc plan`: {}.\n", figures) + entries;
}

}  // namespace rigc::plan
