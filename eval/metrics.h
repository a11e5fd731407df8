// Accuracy metrics (signed-distance statistics, Tanks and Temples precision/recall/F-score) and
// their pictures: CloudCompare-style colours, a coloured PLY, a histogram and a splat render.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "eval/geometry.h"

namespace rigc::eval {

struct DistanceStats {
  std::size_t count = 0;
  double mean = 0, stddev = 0;  // of the signed distance
  double median = 0;            // of the signed distance
  double mean_abs = 0, rms = 0;
  double p90_abs = 0;  // 90th percentile of |d|
  double min = 0, max = 0;
};
// NaNs are skipped. Units in = units out.
DistanceStats distance_stats(const std::vector<double>& d);

// Tanks and Temples: precision = share of reconstructed points within tau of the ground truth,
// recall = share of ground-truth samples within tau of the reconstruction, F = 2PR/(P+R).
struct FScore {
  double tau = 0;
  double precision = 0, recall = 0, fscore = 0;
};
FScore f_score(const std::vector<double>& reconstruction_to_truth,
               const std::vector<double>& truth_to_reconstruction, double tau);

// CloudCompare's default ramp: blue (-range) .. green (0) .. red (+range), through cyan and
// yellow; values beyond the range saturate.
std::array<std::uint8_t, 3> signed_distance_color(double d, double range);

// Binary PLY: float x y z, uchar red green blue, float scalar_signed_distance_mm.
bool write_colored_ply(const std::filesystem::path& path, const std::vector<Vec3>& points,
                       const std::vector<double>& signed_distance_mm, double range_mm,
                       std::string* error);

// A bar chart of the signed distances (mm) with the colour ramp, mean and ± std marks.
bool write_histogram_png(const std::filesystem::path& path, const std::vector<double>& d_mm,
                         double range_mm, const DistanceStats& stats, std::string* error);

// The coloured points splatted over the grey-shaded ground-truth surface, seen by `camera`
// (scaled so the image is at most max_width wide).
// (Eight parameters: the picture's inputs, each used once.)
bool write_heatmap_png(const std::filesystem::path& path, const Surface& surface,
                       const ViewCamera& camera, const std::vector<Vec3>& points,
                       const std::vector<double>& d_mm, double range_mm, int max_width,
                       std::string* error);

}  // namespace rigc::eval
