// What each way the preview differs from Cycles does to a reconstruction (issue #34, item 3;
// measured, not asserted). One scene rendered ten ways, each reconstructed RUNS times (COLMAP is
// not deterministic):
//   preview           as `rigc render` renders it
//   preview-point     its textures and patterns point-sampled (no surface filter)
//   preview-2x2, preview-4x4  each pixel rendered as 2 x 2 or 4 x 4 pixels averaged (shading
//                     and geometry antialiased as a reference's samples do)
//   preview-pixel-lighting  its lights summed for every pixel, not once per 2 x 2 quad
//   preview-hard-shadows  its area lights casting hard shadows (its penumbra filter left out)
//   preview-no-specular   without the lights' specular lobe
//   preview-darker    exposed 0.28 stop less: as dark as Cycles renders the paper scene's statue
//                     (ReferenceAgreement.PaperSceneMasksAndExposure), to weigh that difference
//   cycles            the reference, at SAMPLES samples a pixel
//   cycles-direct     the reference without inter-reflection (direct light only), which the
//                     preview does not model
// Renders resume and COLMAP models are reused, so a rerun only measures again.
// Usage: ablation_table [OUT_DIR] [--scene FILE] [--scale S] [--samples N] [--runs N]
//                       [--only NAME[,NAME...]]
#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "backends/cycles/cycles_backend.h"
#include "backends/preview/preview_backend.h"
#include "compiler/frontend.h"
#include "eval/eval.h"
#include "io/allocator.h"
#include "run/manifest.h"
#include "run/run_loop.h"

namespace {

namespace fs = std::filesystem;

using MakeBackend = std::function<std::unique_ptr<rigc::run::Backend>()>;

struct Way {
  std::string name;
  MakeBackend make;
  std::function<void(rigc::ir::Scene&)> edit = nullptr;  // of the scene it renders, if set

  Way(std::string way_name, MakeBackend make_backend,
      std::function<void(rigc::ir::Scene&)> edit_scene = nullptr)
      : name(std::move(way_name)), make(std::move(make_backend)), edit(std::move(edit_scene)) {}
};

// Area lights of no size: their shadows are hard (their size only sets the preview's penumbrae).
void point_like_lights(rigc::ir::Scene& scene) {
  for (rigc::ir::Light& light : scene.studio.lights) light.size_m = rigc::ir::Vec2::Zero();
}

// A backend of type B with one of its options set by `set`.
template <typename B>
MakeBackend backend_with(std::function<void(B&)> set = nullptr) {
  return [set] {
    auto backend = std::make_unique<B>();
    if (set) set(*backend);
    return backend;
  };
}

// 0.28 stop less light on the sensor (a shorter shutter: the scene is still).
void darker_by_cycles_gap(rigc::ir::Scene& scene) {
  scene.camera.shutter_s *= std::exp2(-0.28);
}

std::vector<Way> ways() {
  using rigc::cycles::CyclesBackend;
  using rigc::preview::PreviewBackend;
  return {
      {"preview", backend_with<PreviewBackend>()},
      {"preview-point",
       backend_with<PreviewBackend>([](auto& b) { b.options.draft_surface = true; })},
      {"preview-2x2", backend_with<PreviewBackend>([](auto& b) { b.options.supersample = 2; })},
      {"preview-4x4", backend_with<PreviewBackend>([](auto& b) { b.options.supersample = 4; })},
      {"preview-pixel-lighting",
       backend_with<PreviewBackend>([](auto& b) { b.options.per_pixel_lighting = true; })},
      {"preview-hard-shadows", backend_with<PreviewBackend>(), point_like_lights},
      {"preview-no-specular",
       backend_with<PreviewBackend>([](auto& b) { b.options.specular = false; })},
      {"preview-darker", backend_with<PreviewBackend>(), darker_by_cycles_gap},
      {"cycles", backend_with<CyclesBackend>()},
      {"cycles-direct", backend_with<CyclesBackend>([](auto& b) { b.max_bounces = 0; })},
  };
}

struct Args {
  fs::path out = "out/ablation-table";
  std::string scene = "scenes/paper-turntable.yaml";
  double scale = 0.25;
  int samples = 16;
  int runs = 2;
  std::string only;
};

Args parse_args(int argc, char** argv) {
  Args args;
  for (int i = 1; i < argc; ++i) {
    const bool has_value = i + 1 < argc;
    if (!std::strcmp(argv[i], "--scene") && has_value) {
      args.scene = argv[++i];
    } else if (!std::strcmp(argv[i], "--scale") && has_value) {
      args.scale = std::atof(argv[++i]);
    } else if (!std::strcmp(argv[i], "--samples") && has_value) {
      args.samples = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--runs") && has_value) {
      args.runs = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--only") && has_value) {
      args.only = argv[++i];
    } else {
      args.out = argv[i];
    }
  }
  return args;
}

bool wanted(const Args& args, const std::string& name) {
  if (args.only.empty()) return true;
  std::stringstream list(args.only);
  for (std::string item; std::getline(list, item, ',');) {
    if (item == name) return true;
  }
  return false;
}

// Renders the scene one way into `dir`; the seconds the renders took, or a negative on failure.
double render(const rigc::ir::Scene& scene, const Way& way, const Args& args, const fs::path& dir) {
  rigc::run::RunOptions options;
  options.output_dir = dir;
  options.settings.scale = args.scale;
  // --samples are the reference's: the preview's ways set their own sample grid.
  options.settings.samples = way.name.starts_with("preview") ? 0 : args.samples;
  std::ofstream log(dir.string() + "-render.log");
  rigc::ir::Scene edited = scene;
  if (way.edit) way.edit(edited);
  const int code = rigc::run::run_backend(edited, *way.make(), options, log);
  if (code != 0) return -1;
  return rigc::run::Manifest::load(dir / "manifest.json").render_seconds();
}

void print_eval_row(const std::string& name, double render_s, int run, const Args& args,
                    const fs::path& dir) {
  rigc::eval::EvalOptions options;
  options.run_dir = dir.string();
  options.scene = args.scene;
  options.output_dir = (dir / fmt::format("eval{}", run)).string();
  options.sfm.reuse_colmap = true;
  options.quiet = true;
  std::ofstream log(options.output_dir + ".log");
  rigc::eval::EvalSummary summary;
  const int code = rigc::eval::evaluate(options, log, &summary);
  if (code != 0 || !summary.reconstructed) {
    fmt::print("{:<14} {:>8.0f} {:>4}  failed: {} (see {}.log)\n", name, render_s, run,
               summary.failure, options.output_dir);
    return;
  }
  fmt::print("{:<14} {:>8.0f} {:>4} {:>5}/{:<3} {:>7} {:>+8.3f} ± {:.3f} {:>7.3f}\n", name,
             render_s, run, summary.registered, summary.images, summary.points, summary.mean_mm,
             summary.std_mm, summary.fscore);
}

}  // namespace

int main(int argc, char** argv) {
  rigc::keep_freed_memory();  // as the rigc command does
  const Args args = parse_args(argc, argv);
  rigc::DiagnosticEngine diag;
  const auto scene = rigc::compile_scene_file(args.scene, diag);
  if (!scene) return 1;
  fs::create_directories(args.out);
  fmt::print("{} at scale {}, Cycles at {} samples a pixel, {} evaluations each\n", scene->name,
             args.scale, args.samples, args.runs);
  fmt::print("{:<14} {:>8} {:>4} {:>9} {:>7} {:>16} {:>7}\n", "way", "render s", "eval",
             "registered", "points", "mean ± std (mm)", "F(1mm)");
  for (const Way& way : ways()) {
    if (!wanted(args, way.name)) continue;
    const fs::path dir = args.out / way.name;
    const double render_s = render(*scene, way, args, dir);
    if (render_s < 0) {
      fmt::print("{:<14} render failed (see {}-render.log)\n", way.name, dir.string());
      continue;
    }
    for (int run = 1; run <= args.runs; ++run) print_eval_row(way.name, render_s, run, args, dir);
    std::fflush(stdout);
  }
  return 0;
}
