// `rigc twin PHOTOS -o DIR` (twin/twin.h).
#include <fmt/format.h>

#include <iostream>

#include "cli/options.h"
#include "cli/verbs.h"
#include "compiler/units.h"
#include "twin/twin.h"

namespace rigc::cli {

int run_twin_command(std::vector<std::string> args) {
  CLI::App app{
      "Make a digital twin of a real capture: the photos' cameras, their silhouettes carved into "
      "a visual hull coloured from the photos, and a scene whose shots are the real cameras "
      "(docs/twin.md).\n\nExample:\n  rigc twin tests/real/templeSparseRing --reference-cameras "
      "tests/real/templeSparseRing/templeSR_par.txt -o out/temple-twin"};
  twin::TwinOptions o;
  std::string height;
  app.add_option("photos", o.photos_dir, "the folder of photos")->required();
  app.add_option("-o,--output", o.output_dir, "the twin's folder")->required();
  app.add_option("--reference-cameras", o.reference_cameras,
                 "calibrated cameras with intrinsics (Middlebury _par.txt, COLMAP model, ...); "
                 "default: COLMAP's registration, scaled by --object-height");
  app.add_option("--masks", o.masks_dir,
                 "object masks made elsewhere (same names; default: a key on the backdrop)");
  app.add_option("--resolution", o.resolution, "voxels along the hull's longest side")
      ->capture_default_str();
  app.add_option("--max-misses", o.max_misses,
                 "silhouettes a hull point may fall outside (a key's errors)")
      ->capture_default_str();
  app.add_option("--object-height", height, "the object's height, for a registration (20cm)");
  app.add_option("--colmap", o.colmap, "COLMAP executable")->capture_default_str();
  app.add_option("--matcher", o.matcher,
                 "a registration's matcher: auto, exhaustive, sequential (rigc eval --help)")
      ->transform(CLI::CheckedTransformer(eval::matcher_names()))
      ->default_str("auto");
  app.add_option("--ring-views", o.ring_views,
                 "also write ring_N.yaml: the twin with N views on the real cameras' ring")
      ->check(CLI::Range(0, 720));
  app.add_flag("!--no-render", o.render,
               "skip rendering the twin, the contact sheet and the lights' scaling to the photos");
  app.add_flag("-q,--quiet", o.quiet, "print errors only");
  if (auto code = parse_options(app, args)) return *code;
  if (!height.empty()) {
    const QuantityParse q = parse_quantity(height, QuantityKind::kLength);
    if (!q.value) {
      std::cerr << "rigc twin: error: --object-height: " << q.error << "\n";
      return 1;
    }
    o.object_height_m = *q.value;
  }
  return twin::make_twin(o, std::cerr);
}

}  // namespace rigc::cli
