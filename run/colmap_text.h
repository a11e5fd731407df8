// The ground truth as a COLMAP text model (sparse/cameras.txt, images.txt, points3D.txt), the
// camera every backend's output is described by, and COLMAP's OPENCV projection.
//
// COLMAP's world is the OBJECT frame (ir.h): SfM on a turntable capture recovers the cameras
// relative to the object, so that is the ground truth to compare with.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "ir/ir.h"

namespace rigc::run {

// File extension of an image format, with the dot: jpeg -> ".jpg", png16 -> ".png",
// tiff16 -> ".tif".
std::string image_extension(ir::ImageFormat format);
// "shot_000.jpg": the image's name inside images/ (COLMAP's NAME).
std::string image_file_name(const ir::Camera& camera, const ir::Shot& shot);
// "images/shot_000.jpg" and "masks/shot_000.png", relative to the run folder.
std::string image_relative_path(const ir::Camera& camera, const ir::Shot& shot);
std::string mask_relative_path(const ir::Shot& shot);

// The camera of the written images at a render scale. The size is rounded
// (max(1, round(width_px * scale))) and the intrinsics follow the rounded size, sx = w_s / w and
// sy = h_s / h, so that the image keeps the field of view (same as dslr::sensor_intrinsics).
// Distortion is zero when camera.effects.distortion is off.
struct OutputCamera {
  std::string model;  // "OPENCV", or "FULL_OPENCV" when k3 != 0 (OPENCV has no k3)
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  ir::Distortion distortion;
  // COLMAP's parameters: OPENCV fx fy cx cy k1 k2 p1 p2; FULL_OPENCV adds k3 k4 k5 k6 (k4..k6 = 0).
  std::vector<double> params() const;
};

// Fails (one-line `error`) when scale is not a positive finite number.
std::optional<OutputCamera> output_camera(const ir::Camera& camera, double scale,
                                          std::string* error);

// The rigid inverse of shot.object_from_camera: COLMAP's camera_from_world.
ir::Mat4 camera_from_object(const ir::Shot& shot);

struct GroundTruthPoints;  // run/ground_truth_points.h

// Writes sparse_dir/{cameras,images,points3D}.txt (creating sparse_dir) for `shots`, indices
// into scene.shots: one camera (CAMERA_ID 1), IMAGE_ID = shot index + 1, NAME = image_file_name.
// With `points` (sampled for these `shots`), points3D.txt holds them (POINT3D_ID = index + 1) with
// their tracks and each image's POINTS2D line their observations; without, both are empty.
// Atomic writes; false with a one-line `error`.
bool write_colmap_sparse(const std::filesystem::path& sparse_dir, const ir::Scene& scene,
                         const std::vector<int>& shots, double scale, std::string* error,
                         const GroundTruthPoints* points = nullptr);

struct ColmapImage {
  int image_id = 0;
  int camera_id = 0;
  std::string name;
  ir::Mat4 camera_from_world = ir::Mat4::Identity();  // from the normalised quaternion and T
  int line = 0;  // of the image in images.txt (0 when read from elsewhere)
};

struct ColmapCamera {
  int camera_id = 0;
  std::string model;
  int width = 0;
  int height = 0;
  std::vector<double> params;
};

// Readers for COLMAP's text format (comments and blank lines skipped; an image's POINTS2D line is
// read and ignored). nullopt with a one-line `error` naming file and line on malformed input.
// A quaternion whose length is within kQuaternionTolerance of 1 (text written with few digits) is
// normalised; a longer or shorter one is an error, as it is no rotation the file's writer meant.
// A camera's focal lengths are at most kMostFocalLengthPerSide times its larger side (a field of
// view under 0.6 degrees), its CAMERA_IDs distinct.
std::optional<std::vector<ColmapImage>> read_colmap_images(const std::filesystem::path& path,
                                                           std::string* error);
std::optional<std::vector<ColmapCamera>> read_colmap_cameras(const std::filesystem::path& path,
                                                             std::string* error);
inline constexpr double kQuaternionTolerance = 1e-3;
inline constexpr double kMostFocalLengthPerSide = 100;

// Every image's CAMERA_ID is among `cameras`; false with "IMAGES_PATH:LINE: image 'NAME' uses
// camera 7, which ... does not define" otherwise.
bool check_camera_ids(const std::vector<ColmapImage>& images,
                      const std::vector<ColmapCamera>& cameras,
                      const std::filesystem::path& images_path, std::string* error);

// COLMAP's projection of a world point, pixel centres at +0.5. `params` in COLMAP order:
// PINHOLE (4: fx fy cx cy), OPENCV (8: + k1 k2 p1 p2) or FULL_OPENCV (12: + k3 k4 k5 k6).
// With x, y the normalised coordinates and r² = x² + y²:
//   x' = x·radial + 2·p1·x·y + p2·(r² + 2x²),  y' = y·radial + p1·(r² + 2y²) + 2·p2·x·y,
//   radial = 1 + k1·r² + k2·r⁴ (FULL_OPENCV: (1 + k1r² + k2r⁴ + k3r⁶) / (1 + k4r² + k5r⁴ + k6r⁶)),
//   u = fx·x' + cx, v = fy·y' + cy.
// NaN for points not in front of the camera (z <= 0) or an unknown parameter count.
ir::Vec2 project_opencv(const std::vector<double>& params, const ir::Mat4& camera_from_world,
                        const ir::Vec3& world_point);

}  // namespace rigc::run
