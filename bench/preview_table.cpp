// Preview backend speed (issue #3 targets, measured, not asserted):
//   paper scene, 18 shots, all effects on, full Canon 6D resolution, 100k-triangle mesh: <= 10 s;
//   the same at 1280 x 853: <= 0.1 s per shot; growth with a 1M-triangle mesh; peak memory < 2 GB.
// Usage: preview_table [SCENE] [--full] [--shots N]
//   without --full only the 1280 px rows run (the full-resolution row takes minutes on 2 cores).
#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include "assets/primitives.h"
#include "backends/preview/preview_backend.h"
#include "compiler/frontend.h"
#include "io/allocator.h"

namespace {

namespace fs = std::filesystem;
using rigc::run::ShotTiming;

// Seconds of CPU (user + system) the process has used: on a shared VM whose speed swings from
// run to run, the CPU a run takes moves less than its wall time does.
double cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  auto seconds = [](const timeval& t) { return t.tv_sec + t.tv_usec / 1e6; };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

struct Row {
  std::string name;
  int shots = 0;
  double seconds = 0;
  double cpu_seconds = 0;
  std::map<std::string, double> stage_ms;
  // A shot's render (its write overlaps the next shot): the first shot's, which pays for the
  // process's fresh memory, and the median of the others.
  double first_shot_ms = 0;
  double other_shots_median_ms = 0;
  // The first shot's stages, and the second's, to see where the first shot's extra time goes.
  std::map<std::string, double> first_shot_stage_ms;
  std::map<std::string, double> second_shot_stage_ms;
};

// The manifest's stages (ShotTiming::stage_ms) under this table's shorter column names, which
// bench/preview_full.sh reads. The preview runs the sensor and the sRGB development as one pass
// (timed as noise): they share a column.
std::map<std::string, double> stages_of(const ShotTiming& t) {
  static const std::map<std::string, std::string> kColumn = {
      {"shadows", "shadows"},
      {"setup", "setup+bin"},
      {"raster_and_shading", "raster+shade"},
      {"exposure", "exposure"},
      {"depth_of_field", "dof"},
      {"diffraction", "diffraction"},
      {"distortion_vignetting", "distortion"},
      {"noise", "noise+develop"},
      {"develop", "noise+develop"},
      {"write", "encode+write"}};
  std::map<std::string, double> columns;
  for (const auto& [stage, ms] : t.stage_ms) columns[kColumn.at(stage)] += ms;
  return columns;
}

Row run(const std::string& name, const rigc::ir::Scene& scene, double scale, int shot_count) {
  const fs::path dir = fs::temp_directory_path() / ("rigc_bench_" + std::to_string(getpid()));
  fs::remove_all(dir);
  rigc::run::RunOptions options;
  options.output_dir = dir;
  options.settings.scale = scale;
  for (int i = 0; i < shot_count && i < static_cast<int>(scene.shots.size()); ++i) {
    options.shots.push_back(i);
  }
  std::vector<ShotTiming> timings;
  std::ostringstream log;
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = cpu_seconds();
  rigc::preview::PreviewBackend backend;
  const int code = rigc::run::run_backend(scene, backend, options, log, &timings);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double cpu = cpu_seconds() - cpu_start;
  fs::remove_all(dir);
  if (code != 0) {
    std::cerr << log.str();
    std::exit(2);
  }
  Row row{name, static_cast<int>(options.shots.size()), seconds, cpu, {}, 0, 0, {}, {}};
  std::vector<double> render_ms;
  for (const auto& t : timings) render_ms.push_back(t.total_ms - t.stage_ms.at("write"));
  if (!render_ms.empty()) {
    row.first_shot_ms = render_ms.front();
    std::vector<double> others(render_ms.begin() + 1, render_ms.end());
    if (!others.empty()) {
      std::nth_element(others.begin(), others.begin() + others.size() / 2, others.end());
      row.other_shots_median_ms = others[others.size() / 2];
    }
  }
  for (const auto& t : timings) {
    for (const auto& [stage, ms] : stages_of(t)) row.stage_ms[stage] += ms;
  }
  if (timings.size() >= 2) {
    row.first_shot_stage_ms = stages_of(timings[0]);
    row.second_shot_stage_ms = stages_of(timings[1]);
  }
  return row;
}

rigc::ir::Scene load(const std::string& path, int statue_detail) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  if (statue_detail > 0) {
    const auto at = yaml.find("detail: ");
    if (at != std::string::npos) yaml.replace(at + 8, 1, std::to_string(statue_detail));
  }
  rigc::DiagnosticEngine diag;
  auto scene = rigc::compile_scene_text(yaml, path, fs::path(path).parent_path().string(), diag);
  if (!scene) std::exit(1);
  return *scene;
}

}  // namespace

int main(int argc, char** argv) {
  rigc::keep_freed_memory();  // as the rigc command does
  std::string scene_path = "scenes/paper-turntable.yaml";
  bool full = false;
  int shots = 18;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--full"))
      full = true;
    else if (!std::strcmp(argv[i], "--shots") && i + 1 < argc)
      shots = std::atoi(argv[++i]);
    else
      scene_path = argv[i];
  }
  std::vector<Row> rows;
  const rigc::ir::Scene scene = load(scene_path, 0);
  const double scale_1280 = 1280.0 / scene.camera.width_px;
  rows.push_back(run(fmt::format("1280 px, {} tris", scene.object.mesh.triangles.size()), scene,
                     scale_1280, shots));
  // Detail 8 of the statue is the 1-million-triangle version of the same object.
  const rigc::ir::Scene big = load(scene_path, 8);
  rows.push_back(run(fmt::format("1280 px, {} tris", big.object.mesh.triangles.size()), big,
                     scale_1280, shots));
  if (full) {
    rows.push_back(run(fmt::format("full res, {} tris", scene.object.mesh.triangles.size()), scene,
                       1.0, shots));
  }
  std::cout << fmt::format("{:<24} {:>5} {:>9} {:>9} {:>9}", "run", "shots", "total s", "s/shot",
                           "cpu s");
  for (const auto& [stage, ms] : rows[0].stage_ms) std::cout << fmt::format(" {:>12}", stage);
  std::cout << '\n';
  for (const auto& row : rows) {
    std::cout << fmt::format("{:<24} {:>5} {:>9.2f} {:>9.3f} {:>9.2f}", row.name, row.shots,
                             row.seconds, row.seconds / row.shots, row.cpu_seconds);
    double sum = 0;
    for (const auto& [stage, ms] : row.stage_ms) sum += ms;
    for (const auto& [stage, ms] : row.stage_ms) {
      std::cout << fmt::format(" {:>11.1f}%", 100 * ms / std::max(sum, 1e-9));
    }
    std::cout << '\n';
  }
  // The same split in milliseconds per shot.
  std::cout << fmt::format("{:<24} {:>35}", "ms per shot", "");
  for (const auto& [stage, ms] : rows[0].stage_ms) std::cout << fmt::format(" {:>12}", stage);
  std::cout << '\n';
  for (const auto& row : rows) {
    std::cout << fmt::format("{:<24} {:>35}", row.name, "");
    for (const auto& [stage, ms] : row.stage_ms) {
      std::cout << fmt::format(" {:>12.1f}", ms / std::max(row.shots, 1));
    }
    std::cout << '\n';
  }
  // The first shot's extra time is mostly fresh memory (bench/results.md).
  for (const auto& row : rows) {
    std::cout << fmt::format("{:<24} first shot {:.0f} ms, other shots median {:.0f} ms\n",
                             row.name, row.first_shot_ms, row.other_shots_median_ms);
  }
  // Rows named "shots 1/2, ..." (bench/preview_full.sh reads the rows that start "full res").
  std::cout << fmt::format("{:<34} {:>25}", "ms in shot 1 / shot 2", "");
  for (const auto& [stage, ms] : rows[0].stage_ms) std::cout << fmt::format(" {:>12}", stage);
  std::cout << '\n';
  for (const auto& row : rows) {
    if (row.first_shot_stage_ms.empty()) continue;
    std::cout << fmt::format("{:<34} {:>25}", "shots 1/2, " + row.name, "");
    for (const auto& [stage, ms] : row.first_shot_stage_ms) {
      std::cout << fmt::format(" {:>5.0f} /{:>5.0f}", ms, row.second_shot_stage_ms.at(stage));
    }
    std::cout << '\n';
  }
  std::cout << fmt::format("peak memory: {:.0f} MB\n", peak_rss_mb());
}
