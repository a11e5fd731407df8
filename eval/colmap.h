// Driving COLMAP's command line (CPU only) as subprocesses, and reading its text models. The
// second stage of `rigc eval`: run_colmap reconstructs the checked inputs.
#pragma once

#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "eval/eval.h"
#include "eval/inputs.h"
#include "eval/photos.h"
#include "ir/ir.h"
#include "run/colmap_text.h"

namespace rigc::eval {

// Runs argv (no shell) with stdout and stderr appended to `log` and QT_QPA_PLATFORM=offscreen
// in the child's environment (unless already set). Returns the exit status, or -1 when the
// program could not be started (then *error says why), 128 + signal when it was killed.
// cpu_seconds (optional) receives the child's user + system CPU time: next to the wall time it
// shows how many cores a step got on a shared machine.
int run_logged(const std::vector<std::string>& argv, const std::filesystem::path& log,
               std::string* error, double* cpu_seconds = nullptr);

// The option names the installed COLMAP accepts (they changed across versions: 3.8 has
// SiftExtraction.use_gpu, newer releases FeatureExtraction.use_gpu).
struct ColmapFlags {
  std::string extraction_gpu;  // "--SiftExtraction.use_gpu"
  std::string matching_gpu;    // "--SiftMatching.use_gpu"
  std::string version;         // first line of `colmap -h`, for the report
  // `matches_importer --match_list_path F --match_type pairs` (matching a given list of pairs).
  bool imports_pair_lists = false;
};
// Probes `executable feature_extractor -h`, `exhaustive_matcher -h` and `matches_importer -h`;
// logs go to log_dir.
// nullopt with a one-line error when COLMAP is missing or does not answer.
std::optional<ColmapFlags> probe_colmap(const std::string& executable,
                                        const std::filesystem::path& log_dir, std::string* error);

// Which image pairs to match when the capture plan is known (a run folder's sparse/images.txt):
// views whose optical axes are close. A turntable's neighbours wrap around, a multi-ring orbit's
// include the rings above and below. Verified matches fall off fast with the angle between two
// views: 45 deg keeps the pairs that still share features on a turntable.
struct NeighbourPairOptions {
  double max_angle_deg = 45;  // pair views up to this angle apart ...
  int max_per_image = 10;     // ... the nearest ones at most (dense captures) ...
  int min_per_image = 2;      // ... and always the nearest ones (sparse captures stay connected)
};
// Pairs (i < j, sorted, unique) of views given their optical axes (unit vectors, world frame).
std::vector<std::pair<int, int>> neighbour_pairs(const std::vector<ir::Vec3>& optical_axes,
                                                 const NeighbourPairOptions& options = {});
// Writes COLMAP's pair list ("name1 name2" per line) for matches_importer; false with a
// one-line `error`.
bool write_pair_list(const std::filesystem::path& path, const std::vector<std::string>& names,
                     const std::vector<std::pair<int, int>>& pairs, std::string* error);

struct Point3D {
  long id = 0;
  ir::Vec3 position = ir::Vec3::Zero();
  std::array<int, 3> rgb{0, 0, 0};
  double error = 0;               // mean reprojection error, pixels
  std::vector<int> track_images;  // IMAGE_IDs observing the point
};

struct SparseModel {
  std::vector<run::ColmapCamera> cameras;
  std::vector<run::ColmapImage> images;
  std::vector<Point3D> points;
  // The camera `image` was taken with, or null when the model has no camera of its id.
  const run::ColmapCamera* camera_of(const run::ColmapImage& image) const;
  double mean_track_length() const;
  double mean_reprojection_error() const;  // over observations, like COLMAP's own report
};

// Reads points3D.txt; nullopt with a one-line error naming file and line.
std::optional<std::vector<Point3D>> read_colmap_points(const std::filesystem::path& path,
                                                       std::string* error);
// Reads cameras.txt, images.txt and points3D.txt of a text model folder.
std::optional<SparseModel> read_sparse_model(const std::filesystem::path& dir, std::string* error);

// One COLMAP reconstruction, as eval.json's "colmap" section reports it.
struct ColmapRun {
  bool ok = false;
  int exit_code = 0;  // when not ok: 1 the input's fault, 2 COLMAP's
  std::string failure;
  nlohmann::json steps = nlohmann::json::array();  // name, seconds, cpu_seconds, exit_code, log
  double seconds = 0;
  std::filesystem::path model_txt;                     // the largest model, as text
  std::filesystem::path images_dir;                    // the images COLMAP read
  nlohmann::json prior;                                // the intrinsics COLMAP started from
  nlohmann::json matching = nlohmann::json::object();  // matcher, pairs and how they were chosen
  bool reused = false;  // --reuse-colmap found a model: the times are the earlier run's
};

// Pairs (i < j, sorted, unique) of a sequence of n views taken in order around a turntable: each
// with the next `overlap`, the last ones with the first (the loop closes).
std::vector<std::pair<int, int>> sequential_ring_pairs(int n, int overlap);

// Features (with the run's camera as the intrinsics prior and its masks), matching, mapper, and
// the text export of the largest model, in OUT/colmap with each step's log in OUT/logs. Photos
// bring their own masks, cameras and capture order (`photos`).
ColmapRun run_colmap(const EvalOptions& options, const EvalInputs& inputs, std::ostream& log,
                     const PhotoSetup* photos = nullptr);

}  // namespace rigc::eval
