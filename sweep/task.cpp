#include "sweep/task.h"

#include <fmt/format.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <sstream>

#include "analysis/coverage.h"
#include "analysis/coverage_output.h"
#include "backends/registry.h"
#include "compiler/frontend.h"
#include "eval/eval.h"
#include "io/atomic_file.h"
#include "run/manifest.h"
#include "run/run_loop.h"
#include "scene/studio_scene.h"

namespace rigc::sweep {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::optional<nlohmann::json> read_json(const fs::path& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void measure_coverage(const ir::Scene& scene, const fs::path& dir, nlohmann::json& result) {
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  const auto start = Clock::now();
  const analysis::CoverageResult coverage =
      analysis::analyse_coverage(scene, studio, analysis::CoverageOptions{});
  std::string error;
  if (!analysis::write_coverage_outputs(scene, studio, coverage, dir / "coverage", 960, &error)) {
    throw std::runtime_error(error);
  }
  double reconstructable = 0;
  for (std::size_t f = 0; f < coverage.views.size(); ++f) {
    if (coverage.reconstructable[f]) reconstructable += coverage.face_area_m2[f];
  }
  const double seen_2 = coverage.shots.empty() ? 0 : coverage.shots.back().seen_2;
  result["coverage_2_views_pct"] = 100 * seen_2;
  result["reconstructable_pct"] = 100 * reconstructable / coverage.total_area_m2;
  result["coverage_s"] = seconds_since(start);
}

// Eval's numbers into `result`; false (and the reason in `result`) when it did not reconstruct.
bool measure_eval(const fs::path& dir, std::ostream& log, nlohmann::json& result) {
  eval::EvalOptions options;
  options.run_dir = dir.string();
  options.scene = (dir / "scene.yaml").string();
  options.output_dir = (dir / "eval").string();
  eval::EvalSummary summary;
  const auto start = Clock::now();
  const int status = eval::evaluate(options, log, &summary);
  result["eval_s"] = seconds_since(start);
  result["images"] = summary.images;
  result["registered"] = summary.registered;
  result["points"] = summary.points;
  if (status != 0 || !summary.reconstructed) {
    result["reason"] =
        "eval: " + (summary.failure.empty() ? fmt::format("exit {}", status) : summary.failure);
    return false;
  }
  result["mean_mm"] = summary.mean_mm;
  result["std_mm"] = summary.std_mm;
  result["fscore"] = summary.fscore;
  return true;
}

// Renders, measures and returns the result (status "ok" or "failed" with a reason).
nlohmann::json run_stages(const nlohmann::json& variant, const fs::path& dir, std::ostream& log) {
  nlohmann::json result = {{"key", variant.at("key")}, {"status", "failed"}};
  DiagnosticEngine diag;
  std::ostringstream diagnostics;
  diag.set_handler([&](const Diagnostic&, const std::string& text) { diagnostics << text; });
  const auto scene = compile_scene_file((dir / "scene.yaml").string(), diag);
  if (!scene) {
    log << diagnostics.str();
    result["reason"] = "the variant's scene does not compile";
    return result;
  }
  const backends::BackendEntry* entry =
      backends::find_backend(variant.at("backend").get<std::string>());
  if (!entry) {
    result["reason"] = "unknown backend";
    return result;
  }
  run::RunOptions options;
  options.output_dir = dir;
  options.settings.scale = variant.at("scale").get<double>();
  options.settings.samples = variant.value("samples", 0);
  const auto start = Clock::now();
  const int render_status = run::run_backend(*scene, *entry->make(), options, log);
  result["render_wall_s"] = seconds_since(start);
  // The images' cost even when a rerun reused them.
  result["render_s"] = run::Manifest::load(dir / "manifest.json").render_seconds();
  if (render_status != 0) {
    result["reason"] = fmt::format("render: exit {} (see the log)", render_status);
    return result;
  }
  if (variant.at("coverage").get<bool>()) measure_coverage(*scene, dir, result);
  if (variant.at("eval").get<bool>() && !measure_eval(dir, log, result)) return result;
  result["status"] = "ok";
  return result;
}

}  // namespace

std::optional<nlohmann::json> read_result(const fs::path& variant_dir, const std::string& key) {
  auto result = read_json(variant_dir / "result.json");
  if (!result || !result->is_object() || result->value("key", "") != key) return std::nullopt;
  return result;
}

bool variant_needs_run(const fs::path& variant_dir, const std::string& key, bool coverage,
                       bool eval) {
  const auto result = read_result(variant_dir, key);
  if (!result || result->value("status", "") != "ok") return true;
  std::error_code ec;
  if (!fs::exists(variant_dir / "manifest.json", ec)) return true;
  if (coverage && !fs::exists(variant_dir / "coverage" / "coverage.json", ec)) return true;
  return eval && !fs::exists(variant_dir / "eval" / "eval.json", ec);
}

int run_variant_task(const fs::path& sweep_dir, int index, std::ostream& log) {
  const auto sweep = read_json(sweep_dir / "sweep.json");
  if (!sweep || !sweep->contains("variants")) {
    log << fmt::format("rigc: error: {} is no sweep folder (no sweep.json)\n", sweep_dir.string());
    return 1;
  }
  const auto& variants = sweep->at("variants");
  if (index < 0 || index >= static_cast<int>(variants.size())) {
    log << fmt::format("rigc: error: the sweep has no variant {}\n", index);
    return 1;
  }
  const fs::path dir = sweep_dir / variants[index].at("name").get<std::string>();
  const auto variant = read_json(dir / "variant.json");
  if (!variant) {
    log << fmt::format("rigc: error: cannot read {}\n", (dir / "variant.json").string());
    return 1;
  }
  std::error_code ec;
  fs::remove(dir / "result.json", ec);
  log << fmt::format("rigc sweep: variant {} ({})\n", index, dir.string());
  nlohmann::json result;
  try {
    result = run_stages(*variant, dir, log);
  } catch (const std::exception& e) {
    result = {{"key", variant->at("key")}, {"status", "failed"}, {"reason", e.what()}};
  }
  std::string error;
  if (!write_file_atomically(dir / "result.json", result.dump(2) + "\n", &error)) {
    log << "rigc: error: " << error << '\n';
    return 2;
  }
  if (result["status"] != "ok") {
    log << fmt::format("rigc sweep: variant {} failed: {}\n", index,
                       result.value("reason", std::string("?")));
    return 2;
  }
  return 0;
}

}  // namespace rigc::sweep
