// Every registered backend's speed (measured, not asserted): time per shot at 1280 x 853 on the
// paper scene, and the ratio to the first backend (the preview), in one run.
// Usage: reference_table [SCENE] [--shots N] [--samples N]
#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "backends/registry.h"
#include "compiler/frontend.h"
#include "io/allocator.h"
#include "run/run_loop.h"

namespace {

namespace fs = std::filesystem;

struct Row {
  std::string backend;
  int shots = 0;
  double seconds = 0;
};

Row measure(const rigc::backends::BackendEntry& entry, const rigc::ir::Scene& scene,
            rigc::run::RunOptions options, int shot_count) {
  const std::string& backend = entry.name;
  const fs::path dir =
      fs::temp_directory_path() / fmt::format("rigc_bench_{}_{}", backend, getpid());
  fs::remove_all(dir);
  options.output_dir = dir;
  for (int i = 0; i < shot_count && i < static_cast<int>(scene.shots.size()); ++i) {
    options.shots.push_back(i);
  }
  std::ostringstream log;
  const auto start = std::chrono::steady_clock::now();
  const int code = rigc::run::run_backend(scene, *entry.make(), options, log);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fs::remove_all(dir);
  if (code != 0) {
    std::cerr << log.str();
    std::exit(2);
  }
  return {backend, static_cast<int>(options.shots.size()), seconds};
}

}  // namespace

int main(int argc, char** argv) {
  rigc::keep_freed_memory();  // as the rigc command does
  std::string scene_path = "scenes/paper-turntable.yaml";
  int shots = 2, samples = 16;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--shots") && i + 1 < argc) {
      shots = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--samples") && i + 1 < argc) {
      samples = std::atoi(argv[++i]);
    } else {
      scene_path = argv[i];
    }
  }
  rigc::DiagnosticEngine diag;
  const auto scene = rigc::compile_scene_file(scene_path, diag);
  if (!scene) return 1;
  const double scale = 1280.0 / scene->camera.width_px;

  rigc::run::RunOptions options;
  options.settings.scale = scale;
  options.settings.samples = samples;
  std::vector<Row> rows;
  for (const auto& entry : rigc::backends::registry()) {
    rows.push_back(measure(entry, *scene, options, shots));
  }
  const double preview_per_shot = rows[0].seconds / rows[0].shots;
  fmt::print(
      "{} at 1280 px wide, {} shots, {} samples per pixel (POV-Ray: antialias depth or "
      "focal-blur samples)\n",
      scene->name, shots, samples);
  fmt::print("{:<10} {:>12} {:>14}\n", "backend", "s per shot", "x preview");
  for (const auto& row : rows) {
    const double per_shot = row.seconds / row.shots;
    fmt::print("{:<10} {:>12.3f} {:>14.1f}\n", row.backend, per_shot, per_shot / preview_per_shot);
  }
  return 0;
}
