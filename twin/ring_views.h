// What-if views for a twin: more cameras on the ring the real ones stood on, each between its two
// real neighbours (by azimuth about the turntable axis): its centre's azimuth, distance and
// height interpolated, its rotation relative to its azimuth slerped. `rigc twin --ring-views N`.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "eval/geometry.h"

namespace rigc::twin {

// `count` cameras at equal azimuth steps from the first real camera's, in the object frame (+Z
// the axis through `axis_point`). Needs 2 real cameras at distinct azimuths; else returns them.
std::vector<eval::ViewCamera> ring_views(const std::vector<eval::ViewCamera>& cameras,
                                         const Eigen::Vector3d& axis_point, int count);

}  // namespace rigc::twin
