// How long the front end takes on big meshes. Target (issue #2): a scene whose mesh has one
// million triangles compiles in under 1 s on the 2-core reference machine.
// Run: ./build/bench/compile_bench  (prints time per compile and the process's peak memory)
#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <sys/resource.h>

#include <filesystem>
#include <fstream>

#include "assets/mesh_io.h"
#include "assets/primitives.h"
#include "compiler/frontend.h"

namespace {

namespace fs = std::filesystem;

// The smallest statue detail with at least a million triangles.
int million_triangle_detail() {
  for (int detail = 1; detail <= 9; ++detail) {
    if (rigc::make_primitive(rigc::PrimitiveKind::kStatue, detail, 1).triangles.size() >= 1000000) {
      return detail;
    }
  }
  return 9;
}

std::string scene_text(const std::string& object_lines) {
  return fmt::format(R"(rigc: 1
object:
{}
  fit: {{height: 30cm}}
  surface: {{pattern: speckle}}
camera:
  body: canon-6d
  lens: {{focal_length: 50mm}}
  exposure: {{aperture: f/8, shutter: 1/125, iso: 200}}
shots:
  - turntable: {{steps: 18, step: 20deg, camera: {{distance: 90cm, height: 15cm}}}}
)",
                     object_lines);
}

void report(benchmark::State& state, const rigc::ir::Scene& scene) {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  state.counters["triangles"] = static_cast<double>(scene.object.mesh.triangles.size());
  state.counters["peak_rss_MB"] = usage.ru_maxrss / 1024.0;
}

void compile_or_skip(benchmark::State& state, const std::string& text) {
  std::optional<rigc::ir::Scene> scene;
  for (auto _ : state) {
    rigc::DiagnosticEngine diag;
    scene = rigc::compile_scene_text(text, "bench.yaml", fs::temp_directory_path().string(), diag);
    if (!scene) {
      state.SkipWithError("scene did not compile");
      return;
    }
    benchmark::DoNotOptimize(scene->object.mesh.triangles.data());
  }
  report(state, *scene);
}

void BM_CompileProceduralStatue1M(benchmark::State& state) {
  compile_or_skip(state, scene_text(fmt::format("  primitive: {{shape: statue, detail: {}}}",
                                                million_triangle_detail())));
}

void BM_CompilePlyFile1M(benchmark::State& state) {
  const fs::path ply = fs::temp_directory_path() / "rigc_bench_statue_1m.ply";
  if (!fs::exists(ply)) {
    std::string error;
    auto mesh = rigc::make_primitive(rigc::PrimitiveKind::kStatue, million_triangle_detail(), 1);
    if (!rigc::write_ply(ply.string(), mesh, &error)) {
      state.SkipWithError(error.c_str());
      return;
    }
  }
  // write_ply keeps RigC's +Z up; PLY files default to +Y up.
  compile_or_skip(state, scene_text(fmt::format("  mesh: {}\n  up: z", ply.string())));
}

}  // namespace

BENCHMARK(BM_CompileProceduralStatue1M)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_CompilePlyFile1M)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_MAIN();
