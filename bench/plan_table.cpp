// Planning speed: the paper scene's statue (detail 6: about 100k triangles; 8: about 1M) planned
// to 90 % from about 50 to 400 candidate poses (five rings, the azimuth step sets the count). The
// target is 10 s or less from 200 candidates at 100k triangles on 2 cores.
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <iostream>

#include "compiler/diagnostics.h"
#include "io/allocator.h"
#include "plan/plan_scene.h"
#include "scene/studio_scene.h"

namespace {

namespace fs = std::filesystem;

std::string paper_scene_text(int detail) {
  return fmt::format(R"(rigc: 1
name: plan-bench
object:
  primitive: {{shape: statue, detail: {}, seed: 7}}
  fit: {{height: 30cm}}
  surface: {{pattern: speckle, scale: 2mm, contrast: 0.7, roughness: 0.8}}
studio:
  turntable: {{diameter: 40cm, height: 75cm}}
  lights:
    - {{type: area, position: [0.7m, -1.3m, 1.3m], size: [50cm, 50cm], power: 80W}}
    - {{type: area, position: [-0.7m, -1.3m, 1.3m], size: [50cm, 50cm], power: 80W}}
  ambient: 20lx
camera:
  body: canon-6d
  lens: {{focal_length: 50mm}}
  exposure: {{aperture: f/13, shutter: 1/125, iso: 200}}
shots:
  - turntable: {{steps: 18, step: 20deg, camera: {{distance: 90cm, height: 15cm}}}}
)",
                     detail);
}

}  // namespace

int main() {
  rigc::keep_freed_memory();  // as the rigc command does
  const fs::path folder = fs::temp_directory_path() / "rigc-plan-bench";
  fs::create_directories(folder);
  std::cout << fmt::format("{:>10} {:>11} {:>12} {:>8} {:>9} {:>7} {:>8}\n", "triangles",
                           "candidates", "coverage s", "search s", "total s", "shots", "recon %");
  for (const int detail : {6, 8}) {
    for (const double step_deg : {36.0, 18.0, 9.0, 4.5}) {
      if (detail == 8 && step_deg < 9) continue;
      rigc::plan::PlanRequest request;
      request.scene_path = (folder / "scene.yaml").string();
      request.output_path = (folder / "planned.yaml").string();
      request.target = 0.9;
      request.candidates.azimuth_step_rad = step_deg * rigc::kDegree;
      std::ofstream(request.scene_path) << paper_scene_text(detail);
      rigc::DiagnosticEngine diag;
      std::string error;
      const auto outcome = rigc::plan::plan_scene(request, diag, &error);
      if (!outcome) {
        std::cerr << "plan_table: " << error << '\n';
        return 1;
      }
      std::cout << fmt::format("{:>10} {:>11} {:>12.2f} {:>8.2f} {:>9.2f} {:>7} {:>8.1f}\n",
                               outcome->scene.object.mesh.triangles.size(),
                               outcome->candidates.candidates.size(), outcome->candidate_seconds,
                               outcome->search_seconds,
                               outcome->candidate_seconds + outcome->search_seconds,
                               outcome->plan.shots.size(), outcome->plan.reconstructable * 100);
    }
  }
  fs::remove_all(folder);
}
