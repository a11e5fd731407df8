// Camera poses another reconstruction tool exported, read into COLMAP's terms (camera_from_world,
// OpenCV axes: +X right, +Y down, +Z forward) so that `rigc eval --reconstruction --cameras` can
// align them to the ground-truth poses:
//   COLMAP text (cameras.txt, images.txt) or binary (cameras.bin, images.bin) model folders;
//   Bundler v0.3 (.out, as Metashape and RealityCapture export) with its image list;
//   Meshroom / AliceVision SfMData JSON (cameras.sfm, sfm.json);
//   Middlebury multi-view calibrations (NAME_par.txt: K, R, t per image);
//   RigC's own cameras.csv (run/camera_csv.h).
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "run/colmap_text.h"

namespace rigc::eval {

struct CameraFile {
  // "COLMAP text", "COLMAP binary", "Bundler", "Meshroom SfMData", "Middlebury",
  // "RigC cameras.csv"
  std::string format;
  std::filesystem::path path;
  std::filesystem::path list;              // Bundler: the image list that was read
  std::vector<run::ColmapImage> images;    // name = the image's file name (no folder)
  std::vector<run::ColmapCamera> cameras;  // when the format gives intrinsics
};

// A camera of known pose: camera_from_world (OpenCV axes), and its intrinsics when the file
// gives them (width and height 0 when it does not say).
struct KnownCamera {
  ir::Mat4 camera_from_world = ir::Mat4::Identity();
  std::optional<run::ColmapCamera> intrinsics;
};
using KnownCameras = std::map<std::string, KnownCamera>;  // by image file name

// The file's cameras by image name.
KnownCameras known_cameras(const CameraFile& file);

// Reads whichever format `path` is: a COLMAP model folder (text or binary) or one of its
// images.txt / images.bin, a Bundler .out (its list: NAME.list.txt, NAME_list.txt or list.txt
// beside it), a Meshroom .sfm / .json, a Middlebury .txt or a RigC .csv. nullopt with a one-line
// error naming the file.
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

// Middlebury multi-view (NAME_par.txt): the image count, then a line per image "NAME k11 .. k33
// r11 .. r33 t1 t2 t3" with x = K [R | t] X. One PINHOLE camera per image (K's skew left out),
// its width and height 0 (the file does not give them).
std::optional<CameraFile> read_middlebury_par(const std::filesystem::path& path,
                                              std::string* error);

// RigC's cameras.csv: centres and omega, phi, kappa in degrees (run/camera_csv.h).
std::optional<std::vector<run::ColmapImage>> read_rigc_camera_csv(const std::filesystem::path& path,
                                                                  std::string* error);

}  // namespace rigc::eval
