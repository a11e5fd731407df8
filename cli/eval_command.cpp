// The `rigc eval` verb.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>

#include "cli/options.h"
#include "cli/verbs.h"
#include "eval/eval.h"
#include "io/input_files.h"

namespace rigc::cli {

using eval::EvalOptions;
using eval::EvalSummary;
using eval::evaluate;

namespace {

// The options for a folder of photos (eval/photos.h).
void add_photo_options(CLI::App& app, eval::EvalOptions& o) {
  app.add_option("--masks", o.photos.masks_dir,
                 "photos: object masks made elsewhere (same names, any common image format; "
                 "default: a chroma key on the backdrop and the still background)");
  app.add_option("--key-tolerance", o.photos.key_tolerance,
                 "photos: the chroma key's tolerance (chromaticity distance to the backdrop)")
      ->check(finite_number())
      ->check(CLI::Range(0.01, 1.0))
      ->capture_default_str();
  app.add_option("--camera", o.photos.camera,
                 "photos: the camera, BODY,FOCAL (e.g. canon-6d,50mm), for photos without EXIF "
                 "(it overrides their EXIF)");
  app.add_option("--reference-cameras", o.photos.reference_cameras,
                 "photos: calibrated cameras to measure the registration against (Middlebury "
                 "_par.txt, COLMAP model folder, Bundler .out with its list, Meshroom .sfm, "
                 "RigC's cameras.csv): rotation, centre and focal errors, relative-pose AUC");
  app.add_flag("--allow-partial", o.photos.allow_partial,
               "exit 0 even when fewer than half of the images register");
}

}  // namespace

void add_eval_options(CLI::App& app, eval::EvalOptions& o) {
  app.add_option("--colmap", o.sfm.colmap, "COLMAP executable")->capture_default_str();
  app.add_option("--matcher", o.sfm.matcher,
                 "feature matching: exhaustive, sequential, neighbours (views whose planned "
                 "optical axes are close, from the run's sparse/images.txt), or auto (neighbours "
                 "for a run folder; for photos sequential in capture order with the loop closed, "
                 "exhaustive up to 10; else exhaustive, sequential above 100 images)")
      ->transform(CLI::CheckedTransformer(eval::matcher_names()))
      ->default_str("auto");
  app.add_option("--neighbour-angle", o.sfm.neighbour_angle_deg,
                 "neighbours: the widest angle (deg) between the optical axes of a matched pair")
      ->check(finite_number())
      ->check(CLI::Range(1.0, 180.0))
      ->capture_default_str();
  app.add_flag("!--no-masks", o.sfm.use_masks, "ignore the run's masks/ (object masks)");
  app.add_flag(
      "--refine-intrinsics", o.sfm.refine_intrinsics,
      "let COLMAP refine the known camera, the run's or a photo body's (default: keep it fixed)");
  app.add_flag("--reuse-colmap", o.sfm.reuse_colmap,
               "reuse the COLMAP model already in the output folder");
  app.add_flag("!--no-icp", o.metrics.icp, "skip the ICP refinement after the camera alignment");
  app.add_flag("--poisson", o.metrics.poisson,
               "also mesh the points (screened Poisson) and compare the mesh, as the paper did");
  app.add_option("--poisson-depth", o.metrics.poisson_depth, "octree depth of the Poisson meshing")
      ->check(CLI::Range(5, 12))
      ->capture_default_str();
  app.add_option("--tau", o.metrics.tau_mm, "F-score distance threshold in mm")
      ->check(positive_number())
      ->capture_default_str();
  app.add_option("--min-track", o.sfm.min_track_length,
                 "measure only COLMAP points seen in at least this many images (2: all of them)")
      ->check(CLI::Range(2, 1000))
      ->capture_default_str();
  app.add_option("--samples", o.metrics.ground_truth_samples,
                 "ground-truth surface samples before the visibility test")
      ->check(CLI::Range(1000, 20000000))
      ->capture_default_str();
  app.add_option("--color-range", o.metrics.color_range_mm,
                 "heat-map range in mm, ± (default: 3 x the RMS distance)")
      ->check(positive_number());
  add_photo_options(app, o);
}

int run_eval_command(std::vector<std::string> args) {
  CLI::App app{
      "Reconstruct a run's images with COLMAP (CPU) and measure the result against the ground "
      "truth: signed point-to-mesh distance (mm), F-score, camera errors; eval.json, a coloured "
      "PLY, a histogram and a heat map."};
  app.footer(
      "\nExample:\n  rigc eval out/paper-turntable/preview        # or --photos DIR --scene SCENE");
  EvalOptions o;
  app.add_option("run", o.run_dir, "run folder (images/, sparse/, manifest.json)");
  app.add_option("--photos", o.photos_dir,
                 "a folder of real photos instead (no ground-truth poses: global registration; "
                 "without --ground-truth or --scene, registration only)");
  app.add_option("--ground-truth", o.ground_truth,
                 "ground-truth mesh (glTF, OBJ, PLY, STL; in its own frame; default: the run's "
                 "scene object in the object frame)");
  app.add_option("--scene", o.scene, "scene file for the ground truth (default: the run's)");
  app.add_option("-o,--output", o.output_dir, "output folder (default: RUN/eval)");
  app.add_option("--reconstruction", o.imported.reconstruction,
                 "measure this point cloud or mesh from another tool (PLY, OBJ, STL, glTF/GLB) "
                 "instead of running COLMAP");
  app.add_option("--cameras", o.imported.cameras,
                 "--reconstruction: the tool's cameras (COLMAP model folder, Bundler .out with "
                 "its list, Meshroom .sfm/.json), aligned to the ground-truth poses (default: "
                 "global registration)");
  app.add_flag("!--no-align", o.imported.align,
               "--reconstruction: the file is in the scene's object frame already");
  app.add_option("--mesh-samples", o.imported.mesh_samples,
                 "--reconstruction: samples of a reconstructed mesh's surface")
      ->check(CLI::Range(1000, 100000000))
      ->capture_default_str();
  app.add_option("--min-fitness", o.imported.min_fitness,
                 "--reconstruction: refuse a registration that puts fewer of the points near the "
                 "ground truth (0..1)")
      ->check(finite_number())
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  add_eval_options(app, o);
  if (auto code = parse_options(app, args)) return *code;
  if (o.run_dir.empty() == o.photos_dir.empty()) {
    std::cerr << "rigc eval: error: give a run folder or --photos DIR (one of them)\n";
    return 1;
  }
  // The files eval reads that gather_inputs (eval/inputs.cpp) does not: no output replaces them.
  protect_input_file(o.imported.reconstruction, "the reconstruction");
  protect_input_file(o.imported.cameras, "the reconstruction's cameras");
  if (!o.run_dir.empty()) {
    protect_input_file(std::filesystem::path(o.run_dir) / "manifest.json", "the run's manifest");
  }
  EvalSummary summary;
  return evaluate(o, std::cerr, &summary);
}

}  // namespace rigc::cli
