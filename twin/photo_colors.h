// The photos projected onto the hull: each vertex takes its colour from the photos that see it
// squarely and closely, weighted towards the best one (docs/twin.md). The lighting of the shoot
// is in those colours: the twin shows the photos' shading, not an albedo.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "eval/geometry.h"
#include "twin/visual_hull.h"

namespace rigc::twin {

// A photo in linear RGB, row-major, with the camera that took it.
struct ColorPhoto {
  eval::ViewCamera camera;
  std::vector<Eigen::Vector3f> linear;  // width x height of the camera
};

// Per vertex of `hull`, its linear colour; vertices no photo sees take the mean of those seen.
std::vector<Eigen::Vector3f> color_vertices(const VisualHull& hull,
                                            const std::vector<ColorPhoto>& photos);

// Vertex normals of a mesh: the area-weighted sum of its triangles' normals, unit length.
std::vector<Eigen::Vector3f> vertex_normals(const VisualHull& hull);

}  // namespace rigc::twin
