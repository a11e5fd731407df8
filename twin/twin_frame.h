// The twin's frames: the real cameras (in the reference's or the registration's frame) turned so
// that the ring they stand on is level (+Z up, the turntable axis) and moved so that the hull
// rests on z = 0 centred over the origin: RigC's object frame (ir/ir.h), in metres.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "eval/geometry.h"

namespace rigc::twin {

// The world's up as the cameras suggest it: the normal of the plane their centres lie nearest to
// (a ring's axis), signed so that most cameras' up (-Y) agrees with it, or, when their up says
// nothing (a rolled camera), so that they look down on the object. With fewer than 3 cameras or
// centres on a line, the mean camera up.
Eigen::Vector3d up_of_cameras(const std::vector<eval::ViewCamera>& cameras,
                              const Eigen::Vector3d& object_centre);

// x -> R * x + t taking the capture's frame to the object frame: `up` to +Z, the turned
// `points` (the hull's vertices) centred over the origin with their lowest at z = 0.
eval::Similarity object_from_capture(const Eigen::Vector3d& up,
                                     const std::vector<Eigen::Vector3f>& points);

// A camera of the capture, seen from the object frame.
eval::ViewCamera in_object_frame(const eval::ViewCamera& camera,
                                 const eval::Similarity& object_from_capture);

}  // namespace rigc::twin
