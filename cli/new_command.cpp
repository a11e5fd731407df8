// `rigc new MODEL [-o scene.yaml]` (plan/starter_scene.h).
#include <fmt/format.h>

#include <filesystem>
#include <iostream>

#include "cli/commands.h"
#include "cli/options.h"
#include "cli/verbs.h"
#include "compiler/units.h"
#include "io/atomic_file.h"
#include "plan/starter_scene.h"

namespace rigc::cli {

namespace fs = std::filesystem;

int run_new_command(std::vector<std::string> args) {
  CLI::App app{
      "Write a commented starting scene for a model file: the camera where the object fills "
      "about 60 % of the frame, an aperture that keeps it sharp, two softboxes, the exposure "
      "check's advice settles, and the planner's shots for 90 % of the surface."};
  app.footer(
      "\nExample:\n  rigc new bunny.obj --height 15cm -o bunny.yaml && rigc check bunny.yaml");
  plan::StarterOptions o;
  std::string height, lens = "50mm", target = "90%";
  app.add_option("model", o.model_path, "model file (glTF/GLB, OBJ, PLY, STL)")->required();
  app.add_option("-o,--output", o.output_path, "scene file to write (default: MODEL's name.yaml)");
  app.add_option("--body", o.body, "camera body preset")->capture_default_str();
  app.add_option("--lens", lens, "the lens's focal length")->capture_default_str();
  app.add_option("--height", height, "the object's height (default: the model file's, in metres)");
  app.add_option("--target", target, "share of the surface the planned shots reconstruct")
      ->capture_default_str();
  if (auto code = parse_options(app, args)) return *code;
  auto quantity = [](const std::string& text, QuantityKind kind, const char* name, double* out) {
    const QuantityParse q = parse_quantity(text, kind);
    if (!q.value) {
      std::cerr << fmt::format("rigc new: error: {}: {}\n", name, q.error);
      return false;
    }
    *out = *q.value;
    return true;
  };
  if (!quantity(lens, QuantityKind::kLength, "--lens", &o.focal_length_m)) return kExitUserError;
  if (!height.empty()) {
    double h = 0;
    if (!quantity(height, QuantityKind::kLength, "--height", &h)) return kExitUserError;
    o.height_m = h;
  }
  const auto share = parse_target(target);
  if (!share) {
    std::cerr << "rigc new: error: --target '" << target << "' is not a share like 90% or 0.9\n";
    return kExitUserError;
  }
  o.target = *share;
  if (!fs::is_regular_file(o.model_path)) {
    std::cerr << fmt::format("rigc new: error: {} is not a model file\n", o.model_path);
    return kExitUserError;
  }
  if (o.output_path.empty()) o.output_path = fs::path(o.model_path).stem().string() + ".yaml";
  if (fs::exists(o.output_path)) {
    std::cerr << fmt::format("rigc new: error: {} exists; give another -o\n", o.output_path);
    return kExitUserError;
  }
  DiagnosticEngine diag;
  std::string error;
  const auto text = plan::starter_scene_text(o, diag, std::cerr, &error);
  if (!text) {
    std::cerr << "rigc new: error: " << error << "\n";
    return kExitUserError;
  }
  if (!write_file_atomically(o.output_path, *text, &error)) {
    std::cerr << "rigc new: error: " << error << "\n";
    return kExitInternalError;
  }
  std::cout << fmt::format("wrote {}: rigc check {} ; rigc studio {}\n", o.output_path,
                           o.output_path, o.output_path);
  return kExitOk;
}

}  // namespace rigc::cli
