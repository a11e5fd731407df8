// Driving COLMAP's command line (CPU only) as subprocesses, and reading its text models.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "backends/common/colmap_text.h"
#include "compiler/ir.h"

namespace rigc::eval {

// Runs argv (no shell) with stdout and stderr appended to `log` and QT_QPA_PLATFORM=offscreen
// in the child's environment (unless already set). Returns the exit status, or -1 when the
// program could not be started (then *error says why), 128 + signal when it was killed.
int run_logged(const std::vector<std::string>& argv, const std::filesystem::path& log,
               std::string* error);

// The option names the installed COLMAP accepts (they changed across versions: 3.8 has
// SiftExtraction.use_gpu, newer releases FeatureExtraction.use_gpu).
struct ColmapFlags {
  std::string extraction_gpu;  // "--SiftExtraction.use_gpu"
  std::string matching_gpu;    // "--SiftMatching.use_gpu"
  std::string version;         // first line of `colmap -h`, for the report
};
// Probes `executable feature_extractor -h` and `exhaustive_matcher -h`; logs go to log_dir.
// nullopt with a one-line error when COLMAP is missing or does not answer.
std::optional<ColmapFlags> probe_colmap(const std::string& executable,
                                        const std::filesystem::path& log_dir, std::string* error);

struct Point3D {
  long id = 0;
  ir::Vec3 position = ir::Vec3::Zero();
  std::array<int, 3> rgb{0, 0, 0};
  double error = 0;               // mean reprojection error, pixels
  std::vector<int> track_images;  // IMAGE_IDs observing the point
};

struct SparseModel {
  std::vector<backends::ColmapCamera> cameras;
  std::vector<backends::ColmapImage> images;
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
