#include "twin/photo_colors.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace rigc::twin {

namespace {

using Vec3 = Eigen::Vector3d;

// Bilinear colour at continuous pixel coordinates (a pixel's centre at +0.5).
Eigen::Vector3f sample(const ColorPhoto& p, double u, double v) {
  const int w = p.camera.width, h = p.camera.height;
  const double x = std::clamp(u - 0.5, 0.0, w - 1.0), y = std::clamp(v - 0.5, 0.0, h - 1.0);
  const int x0 = std::min(static_cast<int>(x), w - 2), y0 = std::min(static_cast<int>(y), h - 2);
  const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
  auto at = [&](int xx, int yy) { return p.linear[static_cast<std::size_t>(yy) * w + xx]; };
  return (at(x0, y0) * (1 - fx) + at(x0 + 1, y0) * fx) * (1 - fy) +
         (at(x0, y0 + 1) * (1 - fx) + at(x0 + 1, y0 + 1) * fx) * fy;
}

// How well `photo` shows each vertex (0 where it does not): the cosine of the viewing angle
// squared times the pixels per metre squared (the area of surface a pixel holds, inverted).
std::vector<double> view_weights(const VisualHull& hull,
                                 const std::vector<Eigen::Vector3f>& normals,
                                 const eval::Surface& surface, const ColorPhoto& photo) {
  const std::size_t n = hull.positions.size();
  const Vec3 eye = photo.camera.center();
  std::vector<Vec3> origins(n), directions(n);
  std::vector<double> distance(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 p = hull.positions[i].cast<double>();
    distance[i] = (eye - p).norm();
    directions[i] = (eye - p) / distance[i];
    origins[i] = p + directions[i] * hull.voxel_m;  // off its own surface
  }
  const eval::RayHits hits = surface.cast_rays(origins, directions);
  std::vector<double> weight(n, 0);
  const Eigen::Matrix3d r = photo.camera.camera_from_world.topLeftCorner<3, 3>();
  const Vec3 t = photo.camera.camera_from_world.topRightCorner<3, 1>();
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
    const double facing = normals[i].cast<double>().dot(directions[i]);
    if (facing <= 0.1 || hits.t[i] < distance[i] - hull.voxel_m) return;
    const Vec3 x = r * hull.positions[i].cast<double>() + t;
    if (x.z() <= 0) return;
    const double u = photo.camera.fx * x.x() / x.z() + photo.camera.cx;
    const double v = photo.camera.fy * x.y() / x.z() + photo.camera.cy;
    if (u < 1 || v < 1 || u > photo.camera.width - 1 || v > photo.camera.height - 1) return;
    const double pixels_per_m = photo.camera.fx / x.z();
    weight[i] = facing * facing * pixels_per_m * pixels_per_m;
  });
  return weight;
}

}  // namespace

std::vector<Eigen::Vector3f> vertex_normals(const VisualHull& hull) {
  std::vector<Eigen::Vector3f> normals(hull.positions.size(), Eigen::Vector3f::Zero());
  for (const auto& t : hull.triangles) {
    const Eigen::Vector3f n = (hull.positions[t[1]] - hull.positions[t[0]])
                                  .cross(hull.positions[t[2]] - hull.positions[t[0]]);
    for (int k = 0; k < 3; ++k) normals[t[k]] += n;
  }
  for (auto& n : normals) {
    const float length = n.norm();
    n = length > 0 ? Eigen::Vector3f(n / length) : Eigen::Vector3f::UnitZ();
  }
  return normals;
}

std::vector<Eigen::Vector3f> color_vertices(const VisualHull& hull,
                                            const std::vector<ColorPhoto>& photos) {
  const std::size_t n = hull.positions.size();
  const auto normals = vertex_normals(hull);
  const eval::Surface surface(hull.positions, hull.triangles);
  std::vector<std::vector<double>> weights;
  for (const auto& photo : photos) weights.push_back(view_weights(hull, normals, surface, photo));
  std::vector<Eigen::Vector3f> colors(n, Eigen::Vector3f::Zero());
  std::vector<char> seen(n, 0);  // not vector<bool>: written in parallel
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
    double best = 0;
    for (const auto& w : weights) best = std::max(best, w[i]);
    if (best <= 0) return;
    // The best photo counts most; those nearly as good blend in, so seams between photos fade.
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double total = 0;
    for (std::size_t k = 0; k < photos.size(); ++k) {
      const double w = std::pow(weights[k][i] / best, 4);
      if (w < 1e-3) continue;
      const Vec3 x = photos[k].camera.camera_from_world.topLeftCorner<3, 3>() *
                         hull.positions[i].cast<double>() +
                     photos[k].camera.camera_from_world.topRightCorner<3, 1>();
      const double u = photos[k].camera.fx * x.x() / x.z() + photos[k].camera.cx;
      const double v = photos[k].camera.fy * x.y() / x.z() + photos[k].camera.cy;
      sum += w * sample(photos[k], u, v).cast<double>();
      total += w;
    }
    colors[i] = (sum / total).cast<float>();
    seen[i] = 1;
  });
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (seen[i]) {
      mean += colors[i].cast<double>();
      ++count;
    }
  }
  if (count) mean /= static_cast<double>(count);
  for (std::size_t i = 0; i < n; ++i) {
    if (!seen[i]) colors[i] = mean.cast<float>();
  }
  return colors;
}

}  // namespace rigc::twin
