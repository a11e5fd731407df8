// A renderer's own noise against the simulated sensor's (measured, not asserted): one shot
// rendered twice with the renderer's seed changed, at each sample setting, with the time a
// render took. `--samples auto` is held to a ratio of at most 0.25 (docs/fidelity.md).
// Usage: noise_table SCENE [--backend NAME] [--scale S] [--shot N] [SAMPLES ...]
//   SAMPLES: counts or auto (default: auto 64); backend default cycles, scale 0.1, shot 0.
#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "backends/registry.h"
#include "compiler/frontend.h"
#include "run/renderer_noise.h"

namespace {

namespace fs = std::filesystem;

struct Arguments {
  std::string scene, backend = "cycles";
  double scale = 0.1;
  int shot = 0;
  std::vector<int> samples;
};

bool parse(int argc, char** argv, Arguments* a) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--backend" && has_value) {
      a->backend = argv[++i];
    } else if (arg == "--scale" && has_value) {
      a->scale = std::atof(argv[++i]);
    } else if (arg == "--shot" && has_value) {
      a->shot = std::atoi(argv[++i]);
    } else if (const auto samples = rigc::run::parse_samples(arg)) {
      a->samples.push_back(*samples);
    } else if (a->scene.empty()) {
      a->scene = arg;
    } else {
      return false;
    }
  }
  if (a->samples.empty()) a->samples = {rigc::run::kConvergedSamples, 64};
  return !a->scene.empty() && a->scale > 0;
}

}  // namespace

int main(int argc, char** argv) {
  Arguments a;
  if (!parse(argc, argv, &a)) {
    std::cerr << "usage: noise_table SCENE [--backend NAME] [--scale S] [--shot N] [SAMPLES ...]\n";
    return 1;
  }
  rigc::DiagnosticEngine diag;
  const auto scene = rigc::compile_scene_file(a.scene, diag);
  const rigc::backends::BackendEntry* entry = rigc::backends::find_backend(a.backend);
  if (!scene || !entry || a.shot < 0 || a.shot >= static_cast<int>(scene->shots.size())) {
    std::cerr << "noise_table: no such scene, backend or shot\n";
    return 1;
  }
  std::cout << fmt::format("{}, {}, scale {}, shot {}\n", scene->name, a.backend, a.scale, a.shot);
  std::cout << "samples | object pixels | renderer / sensor variance | seconds a render\n";
  for (const int samples : a.samples) {
    const fs::path dir = fs::temp_directory_path() / fmt::format("rigc_noise_{}_{}", getpid(),
                                                                 rigc::run::samples_text(samples));
    rigc::run::RenderSettings settings;
    settings.scale = a.scale;
    settings.samples = samples;
    std::string error;
    const auto start = std::chrono::steady_clock::now();
    const auto noise =
        rigc::run::measure_renderer_noise(*scene, *entry->make(), settings, a.shot, dir, &error);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / 2;
    fs::remove_all(dir);
    if (!noise) {
      std::cerr << "noise_table: " << error << '\n';
      return 2;
    }
    std::cout << fmt::format("{} | {} | {:.3f} | {:.1f}\n", rigc::run::samples_text(samples),
                             noise->pixels, noise->ratio(), seconds);
  }
  return 0;
}
