// Coverage analysis speed: 18 turntable shots of a speckled statue at two detail levels for a
// 5472 x 3648 camera; the target is 3 s or less for a million triangles on 2 cores (measured, not
// asserted). Visibility buffers are rendered at --visibility-scale (default: about 1400 px
// across); footprints, angles, focus and exposure are computed per face at full sensor
// resolution. "new ISO s" analyses the scene again at ISO 1600 with the first analysis's shot
// visibility kept (the studio's slider case).
// Usage: coverage_table [--visibility-scale S]
#include <fmt/format.h>

#include <chrono>
#include <cstring>
#include <iostream>
#include <memory>
#include <string>

#include "analysis/coverage.h"
#include "compiler/frontend.h"
#include "io/allocator.h"

namespace {

// A statue on the turntable, 18 shots 20 degrees apart; `detail` sets the triangle count.
std::string statue_scene_text(int detail, int iso) {
  return fmt::format(R"(rigc: 1
object:
  primitive: {{shape: statue, detail: {}}}
  fit: {{height: 30cm}}
  surface: {{pattern: speckle}}
camera:
  body: canon-6d
  lens: {{focal_length: 50mm}}
  exposure: {{aperture: f/13, shutter: 1/125, iso: {}}}
shots:
  - turntable: {{steps: 18, step: 20deg, camera: {{distance: 90cm, height: 15cm}}}}
)",
                     detail, iso);
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

int main(int argc, char** argv) {
  rigc::keep_freed_memory();  // as the rigc command does
  rigc::analysis::CoverageOptions options;
  for (int i = 1; i + 1 < argc; ++i) {
    if (!std::strcmp(argv[i], "--visibility-scale")) {
      options.visibility_scale = std::atof(argv[i + 1]);
    }
  }
  std::string error;
  if (!options.check(&error)) {
    std::cerr << "coverage_table: " << error << '\n';
    return 2;
  }
  std::cout << fmt::format("{:<10} {:>10} {:>8} {:>10} {:>10} {:>10} {:>8}\n", "detail",
                           "triangles", "shots", "prepare s", "analyse s", "new ISO s", ">=2 %");
  for (int detail : {6, 8}) {
    rigc::DiagnosticEngine diag;
    auto scene = rigc::compile_scene_text(statue_scene_text(detail, 200), "bench.yaml", ".", diag);
    auto brighter =
        rigc::compile_scene_text(statue_scene_text(detail, 1600), "bench.yaml", ".", diag);
    if (!scene || !brighter) return 1;
    const auto t0 = std::chrono::steady_clock::now();
    const rigc::scene::StudioScene studio = rigc::scene::prepare_studio_scene(*scene);
    const double prepare_s = seconds_since(t0);
    auto with_cache = options;
    with_cache.visibility_cache = std::make_shared<rigc::analysis::VisibilityCache>();
    const auto t1 = std::chrono::steady_clock::now();
    const auto coverage = rigc::analysis::analyse_coverage(*scene, studio, with_cache);
    const double analyse_s = seconds_since(t1);
    const auto t2 = std::chrono::steady_clock::now();
    rigc::analysis::analyse_coverage(*brighter, studio, with_cache);
    const double new_iso_s = seconds_since(t2);
    std::cout << fmt::format("{:<10} {:>10} {:>8} {:>10.2f} {:>10.2f} {:>10.2f} {:>8.1f}\n", detail,
                             scene->object.mesh.triangles.size(), scene->shots.size(), prepare_s,
                             analyse_s, new_iso_s, 100 * coverage.shots.back().seen_2);
  }
}
