// Driving COLMAP's command line (CPU only) as subprocesses, and reading its text models.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

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
// include the rings above and below. On the paper scene (24 views, 15 deg apart), exhaustive
// matching verified ~1900 matches at 15 deg, ~530 at 30, ~120 at 45, ~20 at 60 and none beyond.
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
  double mean_track_length() const;
  double mean_reprojection_error() const;  // over observations, like COLMAP's own report
};

// Reads points3D.txt; nullopt with a one-line error naming file and line.
std::optional<std::vector<Point3D>> read_colmap_points(const std::filesystem::path& path,
                                                       std::string* error);
// Reads cameras.txt, images.txt and points3D.txt of a text model folder.
std::optional<SparseModel> read_sparse_model(const std::filesystem::path& dir, std::string* error);

}  // namespace rigc::eval
