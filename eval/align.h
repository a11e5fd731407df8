// The third stage of `rigc eval`: the reconstruction in the ground-truth frame. With a run's
// planned cameras, a similarity fitted to the camera centres (RANSAC + Umeyama); for photos, a
// scale from the spread of the clouds, global registration and ICP with scale. Then point-to-plane
// ICP onto the visible ground-truth surface.
#pragma once

#include <Eigen/Geometry>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/colmap.h"
#include "eval/eval.h"
#include "eval/geometry.h"
#include "eval/inputs.h"

namespace rigc::eval {

// Area-uniform samples of the ground truth and those a camera sees: Tanks and Temples' recall
// reference, and the ICP target.
struct SurfaceSamples {
  std::vector<Vec3> all, all_normals;
  std::vector<Vec3> visible, visible_normals;
};

// How the reconstruction reaches the ground-truth frame. kAuto: the cameras when the ground truth
// has poses, else registration (what `rigc eval` does with COLMAP's model).
enum class AlignMethod { kAuto, kCameras, kRegistration, kNone };

struct Alignment {
  bool ok = false;
  std::string failure;
  Similarity transform;           // reconstruction -> ground truth
  nlohmann::json report;          // eval.json's "alignment"
  std::vector<Vec3> points;       // the reconstructed points, aligned
  std::vector<ViewCamera> views;  // the cameras over the ground truth, planned or reconstructed
  SurfaceSamples samples;
  // Share of the aligned points inside object_crop that lie within fitness_distance of the
  // ground-truth surface (measured after the alignment, whichever method it used).
  double fitness = 0;
  double fitness_distance = 0;  // meters
};

// `points`, when given, are the reconstruction's points instead of model.points' positions
// (millions of points from a file need no COLMAP record each).
Alignment align_to_ground_truth(const EvalOptions& options, const SparseModel& model,
                                const GroundTruth& truth, const Surface& surface,
                                AlignMethod method = AlignMethod::kAuto,
                                const std::vector<Vec3>* points = nullptr);

// The region compared: the ground truth's bounds grown by 5 % of their diagonal on every side
// (reconstructed points beyond it are background).
Eigen::AlignedBox3d object_crop(const Surface& surface);

// The `points` inside `box`, in order, filtered in parallel (clouds of millions). With more than
// `limit` inside, every nth of them so that at most `limit` are kept. `indices`, when given, gets
// each kept point's index in `points`.
std::vector<Vec3> points_inside(const std::vector<Vec3>& points, const Eigen::AlignedBox3d& box,
                                std::size_t limit = std::numeric_limits<std::size_t>::max(),
                                std::vector<std::size_t>* indices = nullptr);

// A COLMAP camera's pinhole at a pose: f, cx, cy of the one-focal models (SIMPLE_PINHOLE,
// SIMPLE_RADIAL, RADIAL), fx, fy, cx, cy of the others; distortion left out.
ViewCamera view_camera(const run::ColmapCamera& camera, const Mat4& camera_from_world);

// Where a camera of pose camera_from_world is, in the world.
Vec3 camera_centre(const Mat4& camera_from_world);
double rotation_angle_deg(const Eigen::Matrix3d& r);

}  // namespace rigc::eval
