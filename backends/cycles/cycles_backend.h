// `rigc compile --target cycles` and `rigc render --backend cycles`: the scene as one Python
// script for Blender 3.x (`blender -b --factory-startup --python scene.py`) plus its binary
// geometry (geometry.bin) and textures, rendered by Cycles and developed by the shared DSLR model.
//
// Everything the script needs is one JSON document inside it, written as an escaped Python string
// literal (external::python_string_literal): no user text is ever code. Paths in the script are
// relative to its own folder. Units: Blender's, 1 m per unit; lights in watts (point, spot, area),
// suns in W/m² = lux/683, the ambient as a world of radiance E/(683π), the output EXR in
// W/(m²·sr) = cd/m² / 683.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "backends/external/external_backend.h"
#include "ir/ir.h"

namespace rigc::cycles {

class CyclesBackend : public external::ExternalBackend {
 public:
  std::string name() const override { return "cycles"; }
  std::string executable() const override { return "blender"; }
  std::string package() const override { return "blender"; }
  // Emits a script that renders the unlit albedo (every surface an emitter of its base colour x
  // texture x pattern, no lights or world) instead of the lit image: for the albedo agreement
  // test.
  bool albedo_only = false;
  // Cycles' light paths: 0 renders direct light only (no inter-reflection), for the benchmark
  // that weighs what the preview's lack of indirect light costs (bench/ablation_table.cpp).
  static constexpr int kDefaultMaxBounces = 8;
  int max_bounces = kDefaultMaxBounces;
  std::string options_key() const override;
  static constexpr int kDefaultSamples = 64;
  int default_samples() const override { return kDefaultSamples; }
  // kConvergedSamples: adaptive sampling to converged_noise_threshold, at most this many.
  bool converges() const override { return true; }
  static constexpr int kConvergedMaxSamples = 4096;
  // 2: area lights given their full power on Blender before 4.0.
  int output_version() const override { return 2; }
  // Writes scene.py, geometry.bin and the textures into `dir` (created if missing). `samples` is
  // the script's default Cycles sample count (0: 64).
  bool emit(const ir::Scene& scene, const scene::StudioScene& studio,
            const std::filesystem::path& dir, const run::RenderSettings& settings,
            std::string* error) override;
  // Runs Blender once for the shot's image and mask.
  bool render(const ir::Scene& scene, const scene::StudioScene& studio, const ir::Shot& shot,
              const run::RenderSettings& settings, const run::ShotFiles& files,
              run::RenderedShot* out, std::string* error) override;
};

// Cycles' adaptive-sampling noise threshold that holds its noise variance on the object at most a
// quarter of the camera's sensor noise: Cycles stops a pixel when sum|mean - half-mean| over the
// channels, over the square root of the sum of the means, is below it, which puts a pixel's
// standard deviation near threshold·sqrt(m)/1.38 at mean m; the sensor's shot noise there is
// sqrt(m/g) for g electrons per unit of Cycles' radiance (docs/fidelity.md).
double converged_noise_threshold(const ir::Camera& camera);

// The seed Cycles samples a shot with: the shot's index, offset by the run's seed.
int cycles_seed(std::uint64_t run_seed, int shot_index);

}  // namespace rigc::cycles
