// `rigc sweep`: variants of a scene (a sweep file, or a scene with --vary), each run like
// render + coverage + eval into out/<sweep>/<variant>/, locally or as a Slurm job array, then
// results.csv, results.md and plots side by side.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "cli/commands.h"
#include "cli/options.h"
#include "cli/verbs.h"
#include "compiler/check.h"
#include "compiler/frontend.h"
#include "io/input_files.h"
#include "sweep/local_executor.h"
#include "sweep/results.h"
#include "sweep/slurm_executor.h"
#include "sweep/sweep_spec.h"
#include "sweep/task.h"
#include "sweep/variants.h"

namespace rigc::cli {
namespace {

namespace fs = std::filesystem;

struct SweepArguments {
  std::string input, output, backend = "preview", measure = "coverage";
  Executor executor = Executor::local;
  std::vector<std::string> vary, sbatch;
  std::string partition, time, cpus_per_task, mem;
  double scale = 0.25;
  int samples = 0;
  int jobs = 1;
  bool status = false, retry_failed = false, no_wait = false;
  std::string run_task;
  int task_index = -1;
};

void add_sweep_options(CLI::App& app, SweepArguments& a) {
  app.add_option("input", a.input, "sweep file (rigc-sweep: 1), or a scene file with --vary");
  app.add_option("--vary", a.vary, "PATH=V1,V2,... : an axis on the scene file (repeatable)");
  app.add_option("--backend", a.backend,
                 "with --vary: renderer, or a list (an axis); with a sweep file: run only these "
                 "backends' variants (local)")
      ->capture_default_str();
  app.add_option("--scale", a.scale, "with --vary: render scale")
      ->check(finite_number())
      ->check(CLI::Range(0.01, 4.0))
      ->capture_default_str();
  add_samples_option(app, a.samples,
                     "with --vary: samples per pixel for every backend (0: each backend's "
                     "default; auto: each converged)");
  app.add_option("--measure", a.measure, "with --vary: coverage, eval or coverage,eval")
      ->capture_default_str();
  app.add_option("-o,--output", a.output, "sweep folder (default: out/<sweep>)");
  add_executor_option(app, a.executor, "where variants run");
  app.add_option("--jobs", a.jobs, "local: variants at once (each uses every core already)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_flag("--status", a.status, "print what is done, running and failed, and the results");
  app.add_flag("--retry-failed", a.retry_failed, "slurm: resubmit only the failed tasks");
  app.add_flag("--no-wait", a.no_wait, "slurm: return once the job array is submitted");
  app.add_option("--partition", a.partition, "slurm: sbatch --partition");
  app.add_option("--time", a.time, "slurm: sbatch --time");
  app.add_option("--cpus-per-task", a.cpus_per_task, "slurm: sbatch --cpus-per-task");
  app.add_option("--mem", a.mem, "slurm: sbatch --mem");
  app.add_option("--sbatch", a.sbatch, "slurm: one more sbatch option, e.g. --sbatch=--qos=low")
      ->allow_extra_args(false);
  app.add_option("--run-task", a.run_task, "(internal) run one variant of this sweep folder")
      ->group("");
  app.add_option("--task-index", a.task_index, "(internal) the variant --run-task runs")->group("");
}

// The sweep from --vary and the scene file on the command line.
std::optional<sweep::SweepSpec> spec_from_options(const SweepArguments& a, DiagnosticEngine& diag) {
  sweep::SweepSpec spec;
  spec.scene_path = a.input;
  spec.name = sweep::folder_name(fs::path(a.input).stem().string()) + "-sweep";
  spec.scale = a.scale;
  spec.samples = a.samples;
  std::string error;
  std::optional<sweep::Axis> backends;
  for (const std::string& text : a.vary) {
    auto axis = sweep::parse_vary_option(text, &error);
    if (!axis) {
      std::cerr << "rigc: error: " << error << '\n';
      return std::nullopt;
    }
    if (axis->is_backend()) {
      // `--vary backend=preview,cycles` says what `--backend preview,cycles` says.
      if (backends || a.backend != SweepArguments{}.backend) {
        std::cerr << "rigc: error: the renderers are given twice: by --vary backend=... and "
                     "by --backend (give one)\n";
        return std::nullopt;
      }
      backends = std::move(axis);
      continue;
    }
    spec.axes.push_back(std::move(*axis));
  }
  if (!backends) backends = sweep::parse_vary_option("backend=" + a.backend, &error);
  if (!backends) {
    std::cerr << "rigc: error: --backend: " << error << '\n';
    return std::nullopt;
  }
  if (backends->values.size() > 1) {
    spec.axes.push_back(std::move(*backends));
  } else {
    spec.backend = backends->values.front().text;
    spec.axes.push_back(std::move(*backends));  // checked as an axis, then dropped
  }
  spec.coverage = a.measure.find("coverage") != std::string::npos;
  spec.eval = a.measure.find("eval") != std::string::npos;
  if (a.measure != "coverage" && a.measure != "eval" && a.measure != "coverage,eval" &&
      a.measure != "eval,coverage") {
    std::cerr << fmt::format("rigc: error: --measure '{}' is not coverage, eval or both\n",
                             a.measure);
    return std::nullopt;
  }
  const bool ok = sweep::check_axes(spec, diag);
  if (spec.axes.back().is_backend() && spec.axes.back().values.size() == 1) spec.axes.pop_back();
  if (!ok) return std::nullopt;
  return spec;
}

// The scene's text, read by the front end (bounded) and parsed once, so that a scene too large,
// not YAML or nested too deep is refused at its line before any variant is made.
std::optional<std::string> read_scene_text(const std::string& path, DiagnosticEngine& diag) {
  auto text = read_scene_file(path, diag);
  if (!text || !parse_yaml(*text, path, diag)) return std::nullopt;
  return text;
}

// The backends of `--backend A,B` on a sweep file, each one the sweep renders with; empty (and
// the error said) otherwise.
std::vector<std::string> chosen_backends(const std::string& text,
                                         const std::vector<sweep::Variant>& variants) {
  std::vector<std::string> names;
  std::stringstream list(text);
  for (std::string name; std::getline(list, name, ',');) {
    const bool swept = std::any_of(variants.begin(), variants.end(),
                                   [&](const sweep::Variant& v) { return v.backend == name; });
    if (!swept) {
      std::cerr << fmt::format("rigc: error: --backend: the sweep renders nothing with '{}'\n",
                               name);
      return {};
    }
    names.push_back(name);
  }
  return names;
}

int print_failures(const std::vector<sweep::FailedTask>& failed) {
  for (const auto& f : failed) {
    std::cerr << fmt::format("rigc sweep: variant {} failed{}: {} (log: {})\n", f.variant,
                             f.job.empty() ? "" : " (job " + f.job + ")", f.reason, f.log);
  }
  return failed.empty() ? kExitOk : kExitInternalError;
}

int write_and_summarise(const fs::path& out, const sweep::SweepSpec& spec,
                        const std::vector<sweep::Variant>& variants) {
  const auto rows = sweep::collect_results(out, variants);
  std::string error;
  if (!sweep::write_results(out, spec, rows, &error)) {
    std::cerr << "rigc: error: " << error << '\n';
    return kExitInternalError;
  }
  int ok = 0;
  for (const auto& r : rows) ok += r.ok ? 1 : 0;
  const int best = sweep::best_variant(rows);
  std::cout << fmt::format("rigc sweep: {}/{} variants with results{}; {}\n", ok, rows.size(),
                           best >= 0 ? ", best " + rows[best].variant->name : "",
                           (out / "results.md").string());
  return kExitOk;
}

}  // namespace

int run_sweep_command(std::vector<std::string> args) {
  CLI::App app{
      "Compare capture configurations: run variants of a scene (a sweep file, or a "
      "scene with --vary) locally or on Slurm, and tabulate and plot their results."};
  app.footer(
      "\nExample:\n  rigc sweep scenes/paper-turntable.yaml --vary "
      "camera.exposure.aperture=f/4,f/16");
  SweepArguments a;
  add_sweep_options(app, a);
  if (auto code = parse_options(app, args)) return *code;
  if (!a.run_task.empty()) return sweep::run_variant_task(a.run_task, a.task_index, std::cerr);
  if (a.input.empty()) {
    std::cerr << "rigc: error: give a sweep file, or a scene file with --vary\n";
    return kExitUserError;
  }
  DiagnosticEngine diag;
  const auto spec =
      a.vary.empty() ? sweep::read_sweep_file(a.input, diag) : spec_from_options(a, diag);
  if (!spec) return kExitUserError;
  protect_input_file(a.input, a.vary.empty() ? "the sweep file" : "the scene file");
  protect_input_file(spec->scene_path, "the scene file");
  const auto scene_text = read_scene_text(spec->scene_path, diag);
  if (!scene_text) return kExitUserError;
  const fs::path out =
      a.output.empty() ? fs::path("out") / sweep::folder_name(spec->name) : fs::path(a.output);
  std::vector<sweep::Variant> variants;
  if (!sweep::build_variants(*spec, *scene_text, out, variants, diag)) {
    std::cerr << fmt::format("{} error{}: no variant ran\n", diag.error_count(),
                             diag.error_count() == 1 ? "" : "s");
    return kExitUserError;
  }
  std::string error;
  if (!sweep::write_variant_folders(*spec, variants, out, &error)) {
    std::cerr << "rigc: error: " << error << '\n';
    return kExitUserError;
  }
  const fs::path rigc = fs::read_symlink("/proc/self/exe");
  if (a.status) {
    std::cout << sweep::status_text(out, *spec, variants);
    return write_and_summarise(out, *spec, variants);
  }
  // `--backend` on a sweep file picks which of its variants run.
  const bool backends_chosen = a.vary.empty() && app.count("--backend") > 0;
  if (a.executor == Executor::slurm) {
    if (backends_chosen) {
      std::cerr << "rigc: error: --backend on a sweep file picks variants for the local executor "
                   "only\n";
      return kExitUserError;
    }
    sweep::SlurmOptions slurm;
    slurm.rigc = rigc;
    slurm.wait = !a.no_wait;
    slurm.retry_failed = a.retry_failed;
    for (const auto& [flag, value] : {std::pair{"--partition", a.partition},
                                      {"--time", a.time},
                                      {"--cpus-per-task", a.cpus_per_task},
                                      {"--mem", a.mem}}) {
      if (!value.empty()) slurm.sbatch_args.push_back(std::string(flag) + "=" + value);
    }
    slurm.sbatch_args.insert(slurm.sbatch_args.end(), a.sbatch.begin(), a.sbatch.end());
    const auto outcome = sweep::run_slurm(out, *spec, variants, slurm, std::cerr);
    if (outcome.exit_code != 0 || !slurm.wait) return outcome.exit_code;
    const int written = write_and_summarise(out, *spec, variants);
    return std::max(written, print_failures(outcome.failed));
  }
  if (a.retry_failed || a.no_wait) {
    std::cerr << "rigc: error: --retry-failed and --no-wait are for --executor slurm (a local "
                 "rerun redoes the failed variants by itself)\n";
    return kExitUserError;
  }
  sweep::LocalOptions local{rigc, a.jobs, {}};
  if (backends_chosen) {
    local.backends = chosen_backends(a.backend, variants);
    if (local.backends.empty()) return kExitUserError;
  }
  const auto failed = sweep::run_local(out, *spec, variants, local, std::cerr);
  const int written = write_and_summarise(out, *spec, variants);
  return std::max(written, print_failures(failed));
}

}  // namespace rigc::cli
