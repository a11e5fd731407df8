// The entry points that need eval/ (a library of their own with studio_entries.cpp, so that the
// other harnesses build without them) and the list of every harness.
#include <array>
#include <string>

#include "eval/colmap.h"
#include "fuzz/entries.h"
#include "fuzz/input_file.h"

namespace rigc::fuzz {

std::span<const Harness> harnesses() {
  static constexpr std::array<Harness, 11> kHarnesses{{
      {"scene", scene},
      {"ply", ply},
      {"obj", obj},
      {"stl", stl},
      {"gltf", gltf},
      {"texture", texture},
      {"colmap_cameras", colmap_cameras},
      {"colmap_images", colmap_images},
      {"colmap_points", colmap_points},
      {"manifest", manifest},
      {"studio_edits", studio_edits},
  }};
  return kHarnesses;
}

void colmap_points(std::string_view input) {
  std::string error;
  const auto points = eval::read_colmap_points(write_input(input, "points3D.txt"), &error);
  require_error_if_failed(points, error);
  if (!points) return;
  eval::SparseModel model;
  model.points = *points;
  model.mean_track_length();
  model.mean_reprojection_error();
}

}  // namespace rigc::fuzz
