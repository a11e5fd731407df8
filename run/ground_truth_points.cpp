#include "run/ground_truth_points.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "dslr/develop.h"
#include "scene/studio_scene.h"

namespace rigc::run {

namespace {

using Eigen::Vector3f;

// The object's depth seen by one camera (pinhole: lens distortion moves points by pixels, the
// buffer is coarser), sampled at pixel centres.
class DepthBuffer {
 public:
  DepthBuffer(const OutputCamera& camera, const ir::Mat4& camera_from_object)
      : scale_(std::min(1.0, 640.0 / std::max(1, camera.width))),
        width_(std::max(1, static_cast<int>(std::ceil(camera.width * scale_)))),
        height_(std::max(1, static_cast<int>(std::ceil(camera.height * scale_)))),
        camera_(camera),
        rotation_(camera_from_object.topLeftCorner<3, 3>()),
        translation_(camera_from_object.topRightCorner<3, 1>()),
        depth_(static_cast<std::size_t>(width_) * height_, std::numeric_limits<float>::infinity()) {
  }

  void draw(const std::vector<Vector3f>& positions,
            const std::vector<std::array<std::uint32_t, 3>>& triangles) {
    std::vector<Eigen::Vector3d> screen(positions.size());  // u, v (buffer pixels), depth
    for (std::size_t i = 0; i < positions.size(); ++i) {
      const ir::Vec3 c = rotation_ * positions[i].cast<double>() + translation_;
      screen[i] = {(camera_.fx * c.x() / c.z() + camera_.cx) * scale_,
                   (camera_.fy * c.y() / c.z() + camera_.cy) * scale_, c.z()};
    }
    for (const auto& t : triangles) draw_triangle(screen[t[0]], screen[t[1]], screen[t[2]]);
  }

  // Whether a surface point at `camera_point` (camera frame) is nearer than the surface at the
  // four pixel centres around it, within 0.1 % of the depth and one buffer pixel's footprint: an
  // occluder's edge between a pixel centre and the point still hides it.
  bool unoccluded(const ir::Vec3& camera_point) const {
    const double z = camera_point.z();
    const double u = (camera_.fx * camera_point.x() / z + camera_.cx) * scale_ - 0.5;
    const double v = (camera_.fy * camera_point.y() / z + camera_.cy) * scale_ - 0.5;
    if (!(u > -1 && v > -1 && u < width_ && v < height_)) return true;
    const int x0 = static_cast<int>(std::floor(u)), y0 = static_cast<int>(std::floor(v));
    float nearest = std::numeric_limits<float>::infinity();
    for (int y = std::max(0, y0); y <= std::min(height_ - 1, y0 + 1); ++y) {
      for (int x = std::max(0, x0); x <= std::min(width_ - 1, x0 + 1); ++x) {
        nearest = std::min(nearest, depth_[static_cast<std::size_t>(y) * width_ + x]);
      }
    }
    return z <= nearest + 0.001 * z + z / (camera_.fx * scale_);
  }

  ir::Vec3 to_camera(const ir::Vec3& p) const { return rotation_ * p + translation_; }

 private:
  void draw_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    if (!(a.z() > 1e-6 && b.z() > 1e-6 && c.z() > 1e-6)) return;  // behind or at the camera
    const double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    if (area == 0 || !std::isfinite(area)) return;
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a.x(), b.x(), c.x()}))));
    const int x1 =
        std::min(width_ - 1, static_cast<int>(std::ceil(std::max({a.x(), b.x(), c.x()}))));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a.y(), b.y(), c.y()}))));
    const int y1 =
        std::min(height_ - 1, static_cast<int>(std::ceil(std::max({a.y(), b.y(), c.y()}))));
    for (int y = y0; y <= y1; ++y) {
      const double py = y + 0.5;
      for (int x = x0; x <= x1; ++x) {
        const double px = x + 0.5;
        const double w0 = ((b.x() - px) * (c.y() - py) - (b.y() - py) * (c.x() - px)) / area;
        const double w1 = ((c.x() - px) * (a.y() - py) - (c.y() - py) * (a.x() - px)) / area;
        const double w2 = 1 - w0 - w1;
        if (w0 < 0 || w1 < 0 || w2 < 0) continue;
        const double inverse_depth = w0 / a.z() + w1 / b.z() + w2 / c.z();
        float& d = depth_[static_cast<std::size_t>(y) * width_ + x];
        d = std::min(d, static_cast<float>(1 / inverse_depth));
      }
    }
  }

  double scale_;  // buffer pixels per image pixel
  int width_, height_;
  const OutputCamera& camera_;
  Eigen::Matrix3d rotation_;
  ir::Vec3 translation_;
  std::vector<float> depth_;
};

struct SurfaceSample {
  ir::Vec3 position, normal;
  std::array<std::uint8_t, 3> rgb{0, 0, 0};
};

std::uint8_t srgb_byte(double linear) {
  return static_cast<std::uint8_t>(
      std::lround(255 * std::clamp(dslr::srgb_oetf(std::clamp(linear, 0.0, 1.0)), 0.0, 1.0)));
}

double srgb_to_linear(std::uint8_t byte) {
  const double v = byte / 255.0;
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

// The albedo at a point of triangle `t` with barycentrics (b0, b1, b2).
std::array<std::uint8_t, 3> albedo(const ir::Scene& scene, std::size_t t, const ir::Vec3& p,
                                   double b1, double b2) {
  const ir::Mesh& mesh = scene.object.mesh;
  const int m = t < mesh.triangle_material.size() ? mesh.triangle_material[t] : 0;
  if (m < 0 || m >= static_cast<int>(scene.materials.size())) return {204, 204, 204};
  const ir::Material& material = scene.materials[m];
  // A per-vertex attribute at the point.
  const auto& tri = mesh.triangles[t];
  const auto at_point = [&](const auto& values) {
    return values[tri[0]] * static_cast<float>(1 - b1 - b2) +
           values[tri[1]] * static_cast<float>(b1) + values[tri[2]] * static_cast<float>(b2);
  };
  ir::Vec3 linear = material.base_color;
  if (!mesh.colors.empty()) linear = Eigen::Vector3f(at_point(mesh.colors)).cast<double>();
  const int tex = material.base_color_texture;
  if (tex >= 0 && tex < static_cast<int>(scene.textures.size()) && !mesh.uvs.empty()) {
    const ir::Texture& texture = scene.textures[tex];
    const Eigen::Vector2f uv = at_point(mesh.uvs);
    auto wrap = [](double x, int n) {
      const int i = static_cast<int>(std::floor((x - std::floor(x)) * n));
      return std::clamp(i, 0, n - 1);
    };
    if (texture.width > 0 && texture.height > 0 && texture.channels > 0) {
      const std::size_t texel =
          (static_cast<std::size_t>(wrap(uv.y(), texture.height)) * texture.width +
           wrap(uv.x(), texture.width)) *
          texture.channels;
      for (int c = 0; c < 3; ++c) {
        const int channel = texture.channels >= 3 ? c : 0;
        linear[c] *= srgb_to_linear(texture.pixels[texel + channel]);
      }
    }
  }
  if (scene::has_pattern(material.pattern)) {
    linear *= scene::pattern_factor(material.pattern, p.cast<float>(), 0.0f);
  }
  return {srgb_byte(linear.x()), srgb_byte(linear.y()), srgb_byte(linear.z())};
}

// Area-uniform samples of the object (object frame) with their face normals and colours.
std::vector<SurfaceSample> sample_surface(const ir::Scene& scene,
                                          const std::vector<Vector3f>& positions, int count) {
  const auto& triangles = scene.object.mesh.triangles;
  std::vector<double> cumulative;
  cumulative.reserve(triangles.size());
  double total = 0;
  for (const auto& t : triangles) {
    const Vector3f e1 = positions[t[1]] - positions[t[0]], e2 = positions[t[2]] - positions[t[0]];
    total += 0.5 * e1.cross(e2).cast<double>().norm();
    cumulative.push_back(total);
  }
  std::vector<SurfaceSample> samples;
  if (!(total > 0) || count <= 0) return samples;
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int i = 0; i < count; ++i) {
    const double pick = unit(random) * total;
    const std::size_t t = std::min<std::size_t>(
        std::lower_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin(),
        triangles.size() - 1);
    double r1 = std::sqrt(unit(random)), r2 = unit(random);
    const double b1 = r1 * (1 - r2), b2 = r1 * r2;
    const auto& tri = triangles[t];
    const ir::Vec3 a = positions[tri[0]].cast<double>(), b = positions[tri[1]].cast<double>(),
                   c = positions[tri[2]].cast<double>();
    SurfaceSample s;
    s.position = a + b1 * (b - a) + b2 * (c - a);
    s.normal = (b - a).cross(c - a).normalized();
    if (!s.normal.allFinite()) continue;
    s.rgb = albedo(scene, t, s.position, b1, b2);
    samples.push_back(s);
  }
  return samples;
}

// The samples one shot sees, with their pixels: (sample index, x, y).
struct Seen {
  int sample;
  double x, y;
};
std::vector<Seen> seen_by(const ir::Shot& shot, const OutputCamera& camera,
                          const std::vector<Vector3f>& positions,
                          const std::vector<std::array<std::uint32_t, 3>>& triangles,
                          const std::vector<SurfaceSample>& samples) {
  const ir::Mat4 pose = camera_from_object(shot);
  DepthBuffer depth(camera, pose);
  depth.draw(positions, triangles);
  const ir::Vec3 centre = shot.object_from_camera.topRightCorner<3, 1>();
  const std::vector<double> params = camera.params();
  std::vector<Seen> seen;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const SurfaceSample& s = samples[i];
    const ir::Vec3 to_camera = centre - s.position;
    // Facing the camera, not at a grazing angle (cos > 0.1).
    if (s.normal.dot(to_camera) <= 0.1 * to_camera.norm()) continue;
    const ir::Vec3 c = depth.to_camera(s.position);
    if (!(c.z() > 0)) continue;
    const ir::Vec2 pixel = project_opencv(params, pose, s.position);
    if (!(pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() < camera.width &&
          pixel.y() < camera.height)) {
      continue;
    }
    if (depth.unoccluded(c)) seen.push_back({static_cast<int>(i), pixel.x(), pixel.y()});
  }
  return seen;
}

}  // namespace

GroundTruthPoints sample_ground_truth_points(const ir::Scene& scene, const std::vector<int>& shots,
                                             const OutputCamera& camera, int count) {
  const std::vector<Vector3f> positions = ir::object_frame_positions(scene.object);
  const auto& triangles = scene.object.mesh.triangles;
  const std::vector<SurfaceSample> samples = sample_surface(scene, positions, count);
  std::vector<std::vector<Seen>> seen(shots.size());
  tbb::parallel_for(std::size_t{0}, shots.size(), [&](std::size_t k) {
    seen[k] = seen_by(scene.shots[shots[k]], camera, positions, triangles, samples);
  });
  // Points in sample order, each with its track in shot order.
  std::vector<int> point_of(samples.size(), -1);
  GroundTruthPoints out;
  out.per_image.resize(shots.size());
  for (std::size_t k = 0; k < shots.size(); ++k) {
    for (const Seen& s : seen[k]) {
      if (point_of[s.sample] < 0) {
        point_of[s.sample] = 0;  // marked; numbered below
      }
    }
  }
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (point_of[i] < 0) continue;
    point_of[i] = static_cast<int>(out.points.size());
    out.points.push_back({samples[i].position, samples[i].rgb, {}});
  }
  for (std::size_t k = 0; k < shots.size(); ++k) {
    for (const Seen& s : seen[k]) {
      const int p = point_of[s.sample];
      const int point2d = static_cast<int>(out.per_image[k].size());
      GroundTruthPoint& point = out.points[p];
      out.per_image[k].push_back({p, static_cast<int>(point.track.size())});
      point.track.push_back({static_cast<int>(k), point2d, s.x, s.y});
    }
  }
  return out;
}

}  // namespace rigc::run
