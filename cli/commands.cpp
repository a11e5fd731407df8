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
#include "cli/dispatch.h"
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
using cli::parse_options;

}  // namespace

CLI::Option* add_samples_option(CLI::App& app, int& samples, const std::string& what) {
  const CLI::Validator samples_text(
      [](std::string& text) -> std::string {
        return run::parse_samples(text) ? "" : "'" + text + "' is not a count 0..65536 or auto";
      },
      "N|auto");
  return app
      .add_option_function<std::string>(
          "--samples", [&samples](const std::string& text) { samples = *run::parse_samples(text); },
          what)
      ->check(samples_text);
}

namespace {

// `compile --target BACKEND`: the backend's scripts for the whole scene in `output`.
int emit_scripts(const ir::Scene& scene, const std::string& target, const std::string& output,
                 double scale, int samples) {
  const std::unique_ptr<run::Backend> backend = backends::find_backend(target)->make();
  run::RenderSettings settings;
  settings.scale = scale;
  settings.samples = samples;
  settings = run::settings_for(*backend, settings);
  std::string error;
  if (!backend->check_settings(settings, &error) ||
      !backend->emit(scene, scene::prepare_studio_scene(scene), output, settings, &error)) {
    std::cerr << "rigc: error: " << error << '\n';
    return kExitUserError;
  }
  std::cout << fmt::format("{} files for '{}' in {}\n", target, scene.name, output);
  return kExitOk;
}

int run_compile(std::vector<std::string> args) {
  CLI::App app{"Compile a scene for a target: the IR as JSON, or a backend's scripts."};
  app.footer(
      "\nExample:\n  rigc compile scenes/paper-turntable.yaml --target cycles -o out/paper-cycles");
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
  add_samples_option(app, samples,
                     "renderer samples per pixel (0: the backend's default; auto: until the "
                     "renderer's noise is a quarter of the sensor's)");
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
  app.footer(
      "\nExample:\n  rigc render scenes/paper-turntable.yaml --backend preview --scale 0.25 "
      "--shots 0-3");
  std::string scene_path, backend = "preview", output, shot_text = "all";
  double scale = 1.0;
  std::uint64_t seed = 1;
  app.add_option("scene", scene_path, "scene file (.yaml)")->required();
  int samples = 0;
  app.add_option("--backend", backend, "renderer")
      ->check(CLI::IsMember(backends::backend_names()))
      ->capture_default_str();
  add_samples_option(app, samples,
                     "samples per pixel (0: the backend's default; the preview's: 1, 4, 9, ... as "
                     "a square grid, default 1; auto: until the renderer's noise is a quarter of "
                     "the sensor's, docs/fidelity.md)");
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
  Executor executor = Executor::local;
  std::vector<std::string> sbatch;
  add_executor_option(app, executor, "local, or slurm: a Slurm array task per shot");
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
  if (executor == Executor::slurm) {
    const sweep::SplitRender split{fs::read_symlink("/proc/self/exe"), scene_path, backend, sbatch};
    return sweep::render_on_slurm(*scene, *renderer, options, split, std::cerr);
  }
  return run::run_backend(*scene, *renderer, options, std::cerr);
}

int run_coverage(std::vector<std::string> args) {
  CLI::App app{"Which faces each shot sees, whether SfM can use them, and pictures of it."};
  app.footer("\nExample:\n  rigc coverage scenes/paper-turntable.yaml");
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

}  // namespace

const std::vector<Command>& commands() {
  static const std::vector<Command> table = table_of({
      {"check", run_check_command},
      {"compile", run_compile},
      {"render", run_render},
      {"coverage", run_coverage},
      {"eval", run_eval_command},
      {"compare", run_compare_command},
      {"plan", run_plan_command},
      {"studio", run_studio_command},
      {"sweep", run_sweep_command},
      {"twin", run_twin_command},
      {"new", run_new_command},
      {"version", run_version_command},
  });
  return table;
}

int run_main(std::vector<std::string> args) {
  return dispatch(std::move(args), commands(), nullptr);
}

}  // namespace rigc::cli
