// `rigc eval` and `rigc compare`: reconstruct an image set with COLMAP (CPU), align the
// result to the ground truth, and measure it the way the paper's Table 1 did, plus Tanks and
// Temples' F-score and camera errors.
//
// Output folder (default RUN_DIR/eval):
//   eval.json                    every number, the files and the COLMAP steps with their logs
//   cloud_signed_distance.ply    reconstructed points (object frame, m) coloured by signed distance
//   histogram.png, heatmap.png   the distances as a bar chart and over the ground-truth surface
//   colmap/                      database, masks, models; logs/*.log: each COLMAP step's output
#pragma once

#include <iosfwd>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace rigc::eval {

// How COLMAP pairs the images: automatic picks neighbours when every image has a planned pose,
// else exhaustive, and sequential above 100 images; neighbours pairs nearby views only.
enum class Matcher { automatic, exhaustive, sequential, neighbours };

// Each matcher with its name on the command line ("auto", "exhaustive", ...).
const std::vector<std::pair<std::string, Matcher>>& matcher_names();
std::string matcher_name(Matcher matcher);

// How COLMAP reconstructs the images.
struct SfmOptions {
  std::string colmap = "colmap";
  Matcher matcher = Matcher::automatic;
  double neighbour_angle_deg = 45;  // neighbours: the widest angle between paired optical axes
  bool use_masks = true;            // the run's masks/ (what a green screen gives)
  bool refine_intrinsics = false;   // let COLMAP refine a known (ground-truth) intrinsics prior
  bool reuse_colmap = false;        // skip COLMAP when the output folder has its model already
  // COLMAP's points seen in fewer images are left out: a point triangulated from two views has
  // no third to check it, and the rare false match among them lies centimetres off the surface.
  int min_track_length = 3;
};

// How the reconstruction is compared with the ground truth.
struct MetricOptions {
  bool icp = true;
  bool poisson = false;  // also mesh the points (Open3D's screened Poisson) and compare the mesh
  int poisson_depth = 9;
  double tau_mm = 1.0;                // F-score threshold
  int ground_truth_samples = 200000;  // surface samples before the visibility test
  double color_range_mm = 0;          // heat-map colour range; 0 = 3 x RMS of the distances
};

// --reconstruction: another tool's point cloud or mesh measured instead of running COLMAP
// (eval/reconstruction.h), aligned on its cameras, by registration, or not at all.
struct ImportedOptions {
  std::string reconstruction;
  std::string cameras;         // the tool's camera poses (COLMAP, Bundler, Meshroom)
  bool align = true;           // false: the reconstruction is in the scene's frame (--no-align)
  int mesh_samples = 1000000;  // dense samples of a reconstructed mesh
  double min_fitness = 0.5;    // a registration that fits worse is refused
};

// Photos (eval/photos.h): masks made elsewhere (same stems, any common format) instead of the
// chroma key; the key's tolerance (chromaticity distance); the camera when EXIF has none
// ("canon-6d,50mm"); accept a reconstruction of fewer than half of the photos; calibrated cameras
// to measure the registration against (eval/pose_accuracy.h), in any format eval/camera_files.h
// reads: with them, too few registered photos are triangulated with the reference poses
// (eval/known_poses.h) and no ground-truth mesh is needed.
struct PhotoOptions {
  std::string masks_dir;
  double key_tolerance = 0.12;
  std::string camera;
  bool allow_partial = false;
  std::string reference_cameras;
};

struct EvalOptions {
  std::string run_dir;       // a run folder (images/, sparse/, manifest.json) ...
  std::string photos_dir;    // ... or a folder of photos (no ground-truth poses)
  std::string ground_truth;  // mesh file (its own frame); default: the run's scene object
  std::string scene;         // scene file; default: manifest.json's inputs.source_file
  std::string output_dir;    // default: RUN_DIR/eval (PHOTOS_DIR/eval)
  bool quiet = false;
  SfmOptions sfm;
  MetricOptions metrics;
  ImportedOptions imported;
  PhotoOptions photos;

  // False with a one-line `error` when a field is out of its range or the folders are not one
  // run folder or one photos folder. evaluate() checks it first.
  bool check(std::string* error) const;
};

// The headline numbers (all of them are in `report`, which is eval.json).
struct EvalSummary {
  bool reconstructed = false;
  std::string failure;  // why there are no numbers
  int images = 0, registered = 0;
  long points = 0;
  double mean_mm = 0, std_mm = 0, fscore = 0;
  double colmap_s = 0, rigc_s = 0;
  std::string output_dir, heatmap_png, histogram_png;
  nlohmann::json report;
};

// Runs the whole evaluation, progress and errors to `log`: checks the inputs (eval/inputs.h), runs
// COLMAP (eval/colmap.h), aligns the model to the ground truth (eval/align.h), measures it
// (eval/measure.h) and writes the report (eval/report.h). Returns 0, 1 (user error: bad options or
// folder, no ground truth) or 2 (COLMAP missing or failing, or no reconstruction; the message
// names the log).
int evaluate(const EvalOptions& options, std::ostream& log, EvalSummary* summary);

}  // namespace rigc::eval
