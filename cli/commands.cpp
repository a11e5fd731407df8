#include "cli/commands.h"

#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <regex>

#include "analysis/advice.h"
#include "analysis/coverage.h"
#include "analysis/coverage_output.h"
#include "backends/registry.h"
#include "cli/options.h"
#include "cli/verbs.h"
#include "compiler/frontend.h"
#include "compiler/units.h"
#include "io/atomic_file.h"
#include "ir/ir_json.h"
#include "run/run_loop.h"
#include "run/scene_inputs.h"
#include "run/shots.h"
#include "scene/studio_scene.h"
#include "sweep/split_render.h"

namespace rigc::cli {
namespace {

namespace fs = std::filesystem;

using cli::finite_number;
using cli::non_negative_number;
using cli::parse_options;

// Each diagnostic as JSON; those from first_advice on are advice[i - first_advice], with the
// settings it suggests changing and the values it works out.
nlohmann::json diagnostics_json(const DiagnosticEngine& diag,
                                const std::vector<analysis::Advice>& advice,
                                std::size_t first_advice) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t i = 0; i < diag.diagnostics().size(); ++i) {
    const Diagnostic& d = diag.diagnostics()[i];
    const char* severity = d.severity == Severity::kError     ? "error"
                           : d.severity == Severity::kWarning ? "warning"
                                                              : "note";
    nlohmann::json entry{{"severity", severity},
                         {"file", d.loc.file},
                         {"line", d.loc.line},
                         {"col", d.loc.col},
                         {"message", d.message}};
    if (i >= first_advice && i - first_advice < advice.size()) {
      nlohmann::json changes = nlohmann::json::array();
      for (const analysis::SettingChange& c : advice[i - first_advice].changes) {
        nlohmann::json change{{"setting", analysis::setting_name(c.setting)},
                              {"direction", c.direction > 0 ? "up" : "down"}};
        if (c.value > 0) change["value"] = c.value;
        changes.push_back(change);
      }
      entry["suggestions"] = changes;
    }
    out.push_back(entry);
  }
  return out;
}

int run_check(std::vector<std::string> args) {
  CLI::App app{"Check a scene: report every error and capture warning, like a compiler."};
  std::string scene_path, format = "text";
  bool json = false;
  app.add_option("scene", scene_path, "scene file (.yaml)")->required();
  bool no_advice = false;
  app.add_option("--format", format,
                 "text (file:line:col: diagnostics and a summary line) or json (the diagnostics "
                 "with file, line, column, severity, message and each advice's suggested "
                 "settings, and the compiled scene)")
      ->check(CLI::IsMember({"text", "json"}));
  app.add_flag("--json", json, "the same as --format json");
  app.add_flag("--no-advice", no_advice, "skip the capture advice (coverage, focus, exposure)");
  if (auto code = parse_options(app, args)) return *code;
  json = json || format == "json";

  DiagnosticEngine diag;
  if (json) diag.set_handler([](const Diagnostic&, const std::string&) {});
  auto scene = compile_scene_file(scene_path, diag);
  std::vector<analysis::Advice> advice;
  const std::size_t first_advice = diag.diagnostics().size();
  if (scene && !no_advice) {
    // Capture advice from a coverage analysis at reduced resolution (about 700 px across).
    const scene::StudioScene studio = scene::prepare_studio_scene(*scene);
    analysis::CoverageOptions options;
    options.visibility_scale = std::min(1.0, 700.0 / scene->camera.width_px);
    const analysis::CoverageResult coverage = analysis::analyse_coverage(*scene, studio, options);
    advice = analysis::capture_advice(*scene, studio, coverage);
    for (const analysis::Advice& a : advice) diag.warning(a.loc, a.message);
  }
  if (json) {
    nlohmann::json out{{"ok", scene.has_value()},
                       {"diagnostics", diagnostics_json(diag, advice, first_advice)}};
    if (scene) out["scene"] = ir_to_json(*scene, false);
    std::cout << out.dump(2) << '\n';
    return scene ? kExitOk : kExitUserError;
  }
  if (!scene) {
    std::cerr << fmt::format("{} error{} in {}\n", diag.error_count(),
                             diag.error_count() == 1 ? "" : "s", scene_path);
    return kExitUserError;
  }
  const ir::Camera& c = scene->camera;
  std::cout << fmt::format(
      "{}: ok: '{}', {} shots, object {} ({} triangles, {:.1f} x {:.1f} x {:.1f} cm), {} "
      "{:.0f}mm {} {} ISO {:.0f}, {} lights, {} warning{}\n",
      scene_path, scene->name, scene->shots.size(), scene->object.source,
      scene->object.mesh.triangles.size(),
      100 * (scene->object.bounds_max_object.x() - scene->object.bounds_min_object.x()),
      100 * (scene->object.bounds_max_object.y() - scene->object.bounds_min_object.y()),
      100 * (scene->object.bounds_max_object.z() - scene->object.bounds_min_object.z()),
      c.model.rfind(c.make, 0) == 0 ? c.model : c.make + " " + c.model, c.focal_length_m * 1000,
      format_quantity(c.aperture_f_number, QuantityKind::kFNumber),
      format_quantity(c.shutter_s, QuantityKind::kTime), c.iso, scene->studio.lights.size(),
      diag.warning_count(), diag.warning_count() == 1 ? "" : "s");
  return kExitOk;
}

// `compile --target BACKEND`: the backend's scripts for the whole scene in `output`.
int emit_scripts(const ir::Scene& scene, const std::string& target, const std::string& output,
                 double scale, int samples) {
  const std::unique_ptr<run::Backend> backend = backends::find_backend(target)->make();
  run::RenderSettings settings;
  settings.scale = scale;
  settings.samples = samples;
  std::string error;
  if (!backend->emit(scene, scene::prepare_studio_scene(scene), output, settings, &error)) {
    std::cerr << "rigc: error: " << error << '\n';
    return kExitUserError;
  }
  std::cout << fmt::format("{} files for '{}' in {}\n", target, scene.name, output);
  return kExitOk;
}

int run_compile(std::vector<std::string> args) {
  CLI::App app{"Compile a scene for a target: the IR as JSON, or a backend's scripts."};
  std::string scene_path, target = "ir", output;
  bool no_geometry = false;
  app.add_option("scene", scene_path, "scene file (.yaml)")->required();
  int samples = 0;
  double scale = 1.0;
  std::vector<std::string> targets = backends::backend_names(true);
  targets.insert(targets.begin(), "ir");
  app.add_option("--target,--emit", target, "what to emit: the IR as JSON, or scripts")
      ->check(CLI::IsMember(targets))
      ->capture_default_str();
  app.add_option("-o,--output", output,
                 "output file for ir (default: standard output); folder for a backend's scripts "
                 "(default: out/<scene>/<target>/render)");
  app.add_option("--scale", scale, "multiplies the sensor resolution")
      ->check(finite_number())
      ->check(CLI::Range(0.01, 4.0))
      ->capture_default_str();
  app.add_option("--samples", samples, "renderer samples per pixel (0: the backend's default)")
      ->check(non_negative_number());
  app.add_flag("--no-geometry", no_geometry, "leave vertex and triangle arrays out of the IR");
  if (auto code = parse_options(app, args)) return *code;

  DiagnosticEngine diag;
  auto scene = compile_scene_file(scene_path, diag);
  if (!scene) return kExitUserError;
  run::protect_scene_inputs(scene_path, *scene);
  if (target != "ir") {
    if (output.empty()) output = (fs::path("out") / scene->name / target / "render").string();
    return emit_scripts(*scene, target, output, scale, samples);
  }
  const std::string text = ir_to_json(*scene, !no_geometry).dump(1) + "\n";
  if (output.empty()) {
    std::cout << text;
    return kExitOk;
  }
  std::error_code ec;
  if (fs::equivalent(output, scene_path, ec)) {
    std::cerr << fmt::format("rigc: error: -o {} is the scene file itself\n", output);
    return kExitUserError;
  }
  std::string error;
  if (!rigc::write_file_atomically(output, text, &error)) {
    std::cerr << "rigc: error: " << error << '\n';
    return kExitUserError;
  }
  return kExitOk;
}

int run_render(std::vector<std::string> args) {
  CLI::App app{"Render every shot of a scene with a backend, in RigC's output layout."};
  std::string scene_path, backend = "preview", output, shot_text = "all";
  double scale = 1.0;
  std::uint64_t seed = 1;
  app.add_option("scene", scene_path, "scene file (.yaml)")->required();
  int samples = 0;
  app.add_option("--backend", backend, "renderer")
      ->check(CLI::IsMember(backends::backend_names()))
      ->capture_default_str();
  app.add_option("--samples", samples,
                 "samples per pixel (0: the backend's default; the preview's: 1, 4, 9, ... as "
                 "a square grid, default 1)")
      ->check(non_negative_number());
  app.add_option("-o,--output", output, "run folder (default: out/<scene>/<backend>)");
  app.add_option("--shots", shot_text, "shots to render, e.g. 0,3,5-7 or all")
      ->capture_default_str();
  app.add_option("--scale", scale, "multiplies the sensor resolution, for quick looks")
      ->check(finite_number())
      ->check(CLI::Range(0.01, 4.0))
      ->capture_default_str();
  // Checked as a number 0 or more: CLI11 reads "-1" into an unsigned seed as 2^64 - 1.
  app.add_option("--seed", seed, "sensor noise seed")
      ->check(cli::unsigned_64_number())
      ->capture_default_str();
  bool force = false;
  app.add_flag("--force", force,
               "render into a run folder that holds another scene's shots or files no manifest "
               "lists, deleting them");
  std::string executor = "local";
  std::vector<std::string> sbatch;
  app.add_option("--executor", executor, "local, or slurm: a Slurm array task per shot")
      ->check(CLI::IsMember({"local", "slurm"}))
      ->capture_default_str();
  app.add_option("--sbatch", sbatch, "slurm: an sbatch option, e.g. --sbatch=--time=1:00:00");
  if (auto code = parse_options(app, args)) return *code;

  DiagnosticEngine diag;
  auto scene = compile_scene_file(scene_path, diag);
  if (!scene) return kExitUserError;
  run::protect_scene_inputs(scene_path, *scene);
  std::string error;
  auto shots = run::parse_shot_selection(shot_text, static_cast<int>(scene->shots.size()), &error);
  if (!shots) {
    std::cerr << "rigc: error: --shots: " << error << '\n';
    return kExitUserError;
  }
  run::RunOptions options;
  options.output_dir = output.empty() ? fs::path("out") / scene->name / backend : fs::path(output);
  options.shots = *shots;
  options.settings.scale = scale;
  options.settings.seed = seed;
  options.settings.samples = samples;
  options.progress_bar = isatty(STDERR_FILENO);
  options.force = force;
  const std::unique_ptr<run::Backend> renderer = backends::find_backend(backend)->make();
  if (executor == "slurm") {
    const sweep::SplitRender split{fs::read_symlink("/proc/self/exe"), scene_path, backend, sbatch};
    return sweep::render_on_slurm(*scene, *renderer, options, split, std::cerr);
  }
  return run::run_backend(*scene, *renderer, options, std::cerr);
}

int run_coverage(std::vector<std::string> args) {
  CLI::App app{"Which faces each shot sees, whether SfM can use them, and pictures of it."};
  std::string scene_path, output;
  int picture_width = 960;
  double visibility_scale = 0;
  app.add_option("scene", scene_path, "scene file (.yaml)")->required();
  app.add_option("-o,--output", output, "output folder (default: out/<scene>/coverage)");
  app.add_option("--picture-width", picture_width, "width of the pictures in pixels")
      ->check(CLI::Range(64, 8192))
      ->capture_default_str();
  app.add_option("--visibility-scale", visibility_scale,
                 "resolution of the visibility buffers relative to the sensor (0: ~1400 px)")
      ->check(cli::finite_number_where(
          [](double value) {
            analysis::CoverageOptions options;
            options.visibility_scale = value;
            return options.check();
          },
          "is neither 0 (automatic) nor within 0.01..1", ""));
  if (auto code = parse_options(app, args)) return *code;

  DiagnosticEngine diag;
  auto scene = compile_scene_file(scene_path, diag);
  if (!scene) return kExitUserError;
  run::protect_scene_inputs(scene_path, *scene);
  if (output.empty()) output = (fs::path("out") / scene->name / "coverage").string();
  const scene::StudioScene studio = scene::prepare_studio_scene(*scene);
  analysis::CoverageOptions options;
  options.visibility_scale = visibility_scale;
  const analysis::CoverageResult coverage = analysis::analyse_coverage(*scene, studio, options);
  analysis::report_capture_advice(*scene, studio, coverage, diag);
  std::string error;
  if (!analysis::write_coverage_outputs(*scene, studio, coverage, output, picture_width, &error)) {
    std::cerr << "rigc: error: " << error << '\n';
    return kExitUserError;
  }
  analysis::print_coverage_table(*scene, coverage, std::cout);
  std::cout << fmt::format("coverage of '{}' in {}\n", scene->name, output);
  return kExitOk;
}

int run_version(std::vector<std::string> args) {
  CLI::App app{"Print the version of rigc and of the scene language."};
  if (auto code = parse_options(app, args)) return *code;
  std::cout << fmt::format("rigc {} (scene language 1, IR 1)\n", RIGC_VERSION);
  return kExitOk;
}

}  // namespace

const std::vector<Command>& commands() {
  static const std::vector<Command> table = {
      {"check", "check a scene and report errors and capture warnings", run_check},
      {"compile", "compile a scene to the IR or to a backend's scripts", run_compile},
      {"render", "render every shot with a backend (rigc render --help lists them)", run_render},
      {"coverage", "analyse which faces the shots see and what SfM can use", run_coverage},
      {"eval", "reconstruct a run with COLMAP and measure it against the ground truth",
       run_eval_command},
      {"compare", "render with several backends and compare reconstruction accuracy",
       run_compare_command},
      {"plan", "plan the fewest shots that reach a coverage target", run_plan_command},
      {"studio", "the interactive capture studio in a browser", run_studio_command},
      {"sweep", "compare capture configurations: scene variants, locally or on Slurm",
       run_sweep_command},
      {"twin", "make a digital twin of a real capture (cameras, visual hull, photo colours)",
       run_twin_command},
      {"version", "print the version", run_version},
  };
  return table;
}

int run_main(std::vector<std::string> args) {
  auto usage = [] {
    std::string text = "usage: rigc <command> [options]\n\ncommands:\n";
    for (const auto& c : commands()) text += fmt::format("  {:<10} {}\n", c.name, c.summary);
    text += "\n`rigc <command> --help` describes a command's options.\n";
    return text;
  };
  if (args.size() < 2) {
    std::cerr << usage();
    return kExitUserError;
  }
  const std::string verb = args[1];
  if (verb == "-h" || verb == "--help" || verb == "help") {
    std::cout << usage();
    return kExitOk;
  }
  if (verb == "--version") return run_version({"rigc version"});
  for (const auto& command : commands()) {
    if (command.name != verb) continue;
    std::vector<std::string> verb_args = {"rigc " + verb};
    verb_args.insert(verb_args.end(), args.begin() + 2, args.end());
    try {
      return command.run(verb_args);
    } catch (const fs::filesystem_error& e) {
      // A path the user gave that cannot be followed (a symbolic link loop, no permission):
      // their files, not a bug.
      std::cerr << fmt::format("rigc: error: cannot use '{}': {}\n", e.path1().string(),
                               e.code().message());
      return kExitUserError;
    } catch (const std::exception& e) {
      // Libraries colour their messages (Open3D's errors come as "\e[1;31m[Open3D Error] ...");
      // the terminal codes are dropped.
      const std::string what = std::regex_replace(e.what(), std::regex("\x1b\\[[0-9;]*m"), "");
      std::cerr << "rigc: internal error: " << what << '\n';
      return kExitInternalError;
    }
  }
  std::vector<std::string> names;
  for (const auto& c : commands()) names.push_back(c.name);
  std::string suggestion = closest_match(verb, names);
  std::cerr << fmt::format(
      "rigc: error: unknown command '{}'{}\n\n{}", verb,
      suggestion.empty() ? "" : fmt::format("; did you mean '{}'?", suggestion), usage());
  return kExitUserError;
}

}  // namespace rigc::cli
