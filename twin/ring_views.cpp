#include "twin/ring_views.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace rigc::twin {

namespace {

using Vec3 = Eigen::Vector3d;

// A real camera in cylindrical terms about the axis: its rotation with its azimuth taken out.
struct RingCamera {
  double azimuth = 0, radius = 0, height = 0;
  Eigen::Quaterniond turned_back;  // R Rz(azimuth): the rotation it would have at azimuth 0
  const eval::ViewCamera* camera = nullptr;
};

Eigen::Matrix3d rz(double a) {
  return Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix();
}

}  // namespace

std::vector<eval::ViewCamera> ring_views(const std::vector<eval::ViewCamera>& cameras,
                                         const Vec3& axis_point, int count) {
  std::vector<RingCamera> ring;
  for (const auto& c : cameras) {
    const Vec3 d = c.center() - axis_point;
    RingCamera r;
    r.azimuth = std::atan2(d.y(), d.x());
    if (r.azimuth < 0) r.azimuth += 2 * M_PI;
    r.radius = std::hypot(d.x(), d.y());
    r.height = d.z();
    r.turned_back = Eigen::Quaterniond(
        Eigen::Matrix3d(c.camera_from_world.topLeftCorner<3, 3>() * rz(r.azimuth)));
    r.camera = &c;
    ring.push_back(r);
  }
  std::sort(ring.begin(), ring.end(),
            [](const RingCamera& a, const RingCamera& b) { return a.azimuth < b.azimuth; });
  if (ring.size() < 2 || ring.back().azimuth - ring.front().azimuth < 1e-6 || count < 1) {
    return cameras;
  }
  const double start = std::atan2((cameras.front().center() - axis_point).y(),
                                  (cameras.front().center() - axis_point).x());
  std::vector<eval::ViewCamera> out;
  for (int k = 0; k < count; ++k) {
    double a = std::fmod(start + 2 * M_PI * k / count + 4 * M_PI, 2 * M_PI);
    // The real neighbours on either side (wrapping past 2 pi).
    std::size_t j = 0;
    while (j < ring.size() && ring[j].azimuth <= a) ++j;
    const RingCamera& hi = ring[j % ring.size()];
    const RingCamera& lo = ring[(j + ring.size() - 1) % ring.size()];
    double span = hi.azimuth - lo.azimuth, offset = a - lo.azimuth;
    if (span <= 0) span += 2 * M_PI;
    if (offset < 0) offset += 2 * M_PI;
    const double t = std::clamp(offset / span, 0.0, 1.0);
    eval::ViewCamera c = *lo.camera;
    const double radius = (1 - t) * lo.radius + t * hi.radius;
    const double height = (1 - t) * lo.height + t * hi.height;
    const Vec3 centre = axis_point + Vec3(radius * std::cos(a), radius * std::sin(a), height);
    const Eigen::Matrix3d r =
        lo.turned_back.slerp(t, hi.turned_back).toRotationMatrix() * rz(a).transpose();
    c.camera_from_world.topLeftCorner<3, 3>() = r;
    c.camera_from_world.topRightCorner<3, 1>() = -r * centre;
    out.push_back(c);
  }
  return out;
}

}  // namespace rigc::twin
