#include "twin/twin_frame.h"

#include <Eigen/Dense>

namespace rigc::twin {

using Vec3 = Eigen::Vector3d;

Vec3 up_of_cameras(const std::vector<eval::ViewCamera>& cameras, const Vec3& object_centre) {
  Vec3 mean_up = Vec3::Zero(), mean_centre = Vec3::Zero();
  for (const auto& c : cameras) {
    mean_up -= c.camera_from_world.topLeftCorner<3, 3>().row(1).transpose();
    mean_centre += c.center();
  }
  if (cameras.empty()) return Vec3::UnitZ();
  mean_centre /= static_cast<double>(cameras.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& c : cameras) {
    const Vec3 d = c.center() - mean_centre;
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  const Vec3 spread = solver.eigenvalues();  // ascending
  if (cameras.size() < 3 || !(spread(1) > 1e-6 * spread(2))) {
    return mean_up.norm() > 0 ? Vec3(mean_up.normalized()) : Vec3::UnitZ();
  }
  Vec3 normal = solver.eigenvectors().col(0).normalized();
  const double agreement = normal.dot(mean_up) / static_cast<double>(cameras.size());
  if (std::abs(agreement) > 0.3) return agreement > 0 ? normal : Vec3(-normal);
  return (mean_centre - object_centre).dot(normal) >= 0 ? normal : Vec3(-normal);
}

eval::Similarity object_from_capture(const Vec3& up, const std::vector<Eigen::Vector3f>& points) {
  eval::Similarity s;
  s.rotation =
      Eigen::Quaterniond::FromTwoVectors(up.normalized(), Vec3::UnitZ()).toRotationMatrix();
  Eigen::AlignedBox3d turned;
  for (const auto& p : points) turned.extend(s.rotation * p.cast<double>());
  s.translation = Vec3(-turned.center().x(), -turned.center().y(), -turned.min().z());
  return s;
}

eval::ViewCamera in_object_frame(const eval::ViewCamera& camera, const eval::Similarity& s) {
  eval::ViewCamera c = camera;
  const Eigen::Matrix3d r = camera.camera_from_world.topLeftCorner<3, 3>() * s.rotation.transpose();
  c.camera_from_world.topLeftCorner<3, 3>() = r;
  c.camera_from_world.topRightCorner<3, 1>() = -r * s.apply(camera.center());
  return c;
}

}  // namespace rigc::twin
