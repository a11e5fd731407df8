// Camera poses another reconstruction tool exported, read into COLMAP's terms (camera_from_world,
// OpenCV axes: +X right, +Y down, +Z forward) so that `rigc eval --reconstruction --cameras` can
// align them to the ground-truth poses:
//   COLMAP text (cameras.txt, images.txt) or binary (cameras.bin, images.bin) model folders;
//   Bundler v0.3 (.out, as Metashape and RealityCapture export) with its image list;
//   Meshroom / AliceVision SfMData JSON (cameras.sfm, sfm.json).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "run/colmap_text.h"

namespace rigc::eval {

struct CameraFile {
  std::string format;  // "COLMAP text", "COLMAP binary", "Bundler", "Meshroom SfMData"
  std::filesystem::path path;
  std::filesystem::path list;              // Bundler: the image list that was read
  std::vector<run::ColmapImage> images;    // name = the image's file name (no folder)
  std::vector<run::ColmapCamera> cameras;  // when the format gives intrinsics
};

// Reads whichever format `path` is: a COLMAP model folder (text or binary) or one of its
// images.txt / images.bin, a Bundler .out (its list: NAME.list.txt, NAME_list.txt or list.txt
// beside it), or a Meshroom .sfm / .json. nullopt with a one-line error naming the file.
std::optional<CameraFile> read_camera_file(const std::filesystem::path& path, std::string* error);

// COLMAP binary models (cameras.bin, images.bin) as COLMAP 3.x writes them.
std::optional<std::vector<run::ColmapCamera>> read_colmap_cameras_bin(
    const std::filesystem::path& path, std::string* error);
std::optional<std::vector<run::ColmapImage>> read_colmap_images_bin(
    const std::filesystem::path& path, std::string* error);

// Bundler v0.3: cameras in `out_path` (f k1 k2, R, t; camera looks down -Z with +Y up), names in
// `list_path` (first word of each line), one line per camera. Cameras Bundler did not register
// (all zero) are left out.
std::optional<std::vector<run::ColmapImage>> read_bundler(const std::filesystem::path& out_path,
                                                          const std::filesystem::path& list_path,
                                                          std::string* error);

// Meshroom SfMData JSON: views (path, poseId) and poses (rotation: world-to-camera, stored
// column-major; center).
std::optional<std::vector<run::ColmapImage>> read_meshroom_sfm(const std::filesystem::path& path,
                                                               std::string* error);

}  // namespace rigc::eval
