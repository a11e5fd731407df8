// The ground truth as a Bundler v0.3 model (bundle.out and its image list), the camera format
// Metashape and RealityCapture import, with the ground-truth points and their views.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "ir/ir.h"
#include "run/ground_truth_points.h"

namespace rigc::run {

// bundle.out: per camera "f k1 k2", R (3 rows), t, with Bundler's camera looking down -Z, +Y up
// (the OpenCV pose with its Y and Z rows negated), f = fx of output_camera at `scale`, k1 k2 its
// radial distortion; then the points: position, colour, views as "camera key x y" with x, y from
// the image centre, +y up. The list has one line per camera: its image path relative to the run
// folder ("images/shot_000.jpg"). Atomic writes; false with a one-line `error`.
// Why Bundler cannot describe `camera` (empty when it can): its cameras have one focal length
// and the principal point at the image centre. The tolerances keep a body's cameras, whose fx
// and fy differ by the rounding of the sensor's size in millimetres (0.14 % for the Canon 6D).
std::string bundler_camera_problem(const ir::Camera& camera, double scale);

// (Seven parameters: the two files it writes and what they describe.)
bool write_bundler(const std::filesystem::path& out_path, const std::filesystem::path& list_path,
                   const ir::Scene& scene, const std::vector<int>& shots, double scale,
                   const GroundTruthPoints& points, std::string* error);

}  // namespace rigc::run
