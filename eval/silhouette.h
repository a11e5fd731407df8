// A silhouette: per pixel, how much of it is the object (0..1), as a mask file holds it or a mesh
// casts it; and how much two of them overlap. eval's keyed masks are judged by it, and the
// twin's hull is carved from and compared with it (twin/visual_hull.h).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rigc::eval {

struct Silhouette {
  int width = 0, height = 0;
  std::vector<float> coverage;  // row-major
  float at(int x, int y) const { return coverage[static_cast<std::size_t>(y) * width + x]; }
};

// A mask file as a silhouette (its first channel, 0..1); nullopt with `error`.
std::optional<Silhouette> read_silhouette(const std::filesystem::path& path, std::string* error);

// Intersection over union of two silhouettes of one size, each thresholded at half (1 when
// neither holds any object).
double silhouette_iou(const Silhouette& a, const Silhouette& b);

}  // namespace rigc::eval
