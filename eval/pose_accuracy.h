// How close a reconstruction's cameras are to reference cameras (a calibrated rig, another tool's
// model, a run's ground truth) when there is no ground-truth surface to measure: each photo's
// rotation and centre error after a similarity fit, the focal-length error, and the area under
// the recall curve of relative pose errors as COLMAP's benchmark reports it
// (benchmark/reconstruction/evaluation/utils.py: compute_grouped_rel_errors, compute_auc).
#pragma once

#include <array>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "eval/camera_files.h"
#include "eval/geometry.h"
#include "run/colmap_text.h"

namespace rigc::eval {

// One photo against its reference camera. The errors are NaN when it did not register.
struct PhotoPoseError {
  std::string name;
  bool registered = false;
  double rotation_deg = 0;
  double centre_m = 0;        // in the reference's frame (metres when the reference is metric)
  double centre_percent = 0;  // of the reference camera's distance to the object
  double focal_percent = 0;   // (estimated fx - reference fx) / reference fx; NaN if unknown
};

struct PoseAccuracy {
  bool ok = false;
  std::string failure;
  Similarity reference_from_reconstruction;
  Vec3 object_centre = Vec3::Zero();   // where the reference cameras' optical axes meet
  std::vector<PhotoPoseError> photos;  // in `names` order
  static constexpr std::array<double, 4> kAucThresholdsDeg{1, 2, 5, 10};
  std::array<double, 4> auc{};  // percent, at kAucThresholdsDeg
  nlohmann::json report;        // eval.json's "cameras" section
};

// COLMAP's relative pose error of every ordered pair of `names`: max(rotation angle, angle
// between the relative translations) in degrees, 180 for a pair not both in `estimated`.
std::vector<double> relative_pose_errors(const std::vector<std::string>& names,
                                         const KnownCameras& reference,
                                         const std::map<std::string, Mat4>& estimated);

// Area under the recall curve up to each threshold, in percent (COLMAP's compute_auc with no
// minimum error): the recall of the sorted errors integrated by the trapezoid rule.
std::vector<double> pose_auc(std::vector<double> errors, const std::vector<double>& thresholds);

// The point nearest to every camera's optical axis in the least-squares sense: the object a ring
// of cameras looks at. nullopt when the axes are (nearly) parallel.
std::optional<Vec3> point_nearest_axes(const std::vector<Mat4>& camera_from_world);

// Measures the `estimated` cameras (a reconstruction's, any frame and scale) against `reference`
// for the photos `names` (each must have a reference camera). Needs 3 registered photos with
// distinct centres for the similarity.
PoseAccuracy measure_pose_accuracy(
    const std::vector<std::string>& names, const KnownCameras& reference,
    const std::map<std::string, Mat4>& estimated,
    const std::map<std::string, run::ColmapCamera>& estimated_intrinsics);

}  // namespace rigc::eval
