#include "run/camera_csv.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "io/atomic_file.h"
#include "run/colmap_text.h"

namespace rigc::run {

namespace {

// OpenCV's camera axes to photogrammetry's (+Y up, +Z backward).
Eigen::Matrix3d flip_yz() {
  return Eigen::Vector3d(1, -1, -1).asDiagonal();
}

double degrees(double radians) {
  return radians * 180 / M_PI;
}

}  // namespace

ir::Vec3 omega_phi_kappa(const Eigen::Matrix3d& camera_from_world) {
  const Eigen::Matrix3d m = camera_from_world.transpose() * flip_yz();  // camera-to-world
  const double phi = std::asin(std::clamp(m(0, 2), -1.0, 1.0));
  const double kappa = std::atan2(-m(0, 1), m(0, 0));
  const double omega = std::atan2(-m(1, 2), m(2, 2));
  return {omega, phi, kappa};
}

Eigen::Matrix3d rotation_from_omega_phi_kappa(const ir::Vec3& a) {
  const Eigen::Matrix3d m =
      (Eigen::AngleAxisd(a.x(), ir::Vec3::UnitX()) * Eigen::AngleAxisd(a.y(), ir::Vec3::UnitY()) *
       Eigen::AngleAxisd(a.z(), ir::Vec3::UnitZ()))
          .toRotationMatrix();
  return flip_yz() * m.transpose();
}

bool write_camera_csv(const std::filesystem::path& path, const ir::Scene& scene,
                      const std::vector<int>& shots, std::string* error) {
  std::string text =
      "# RigC ground-truth cameras: object frame (+Z up, meters); omega, phi, kappa in degrees: "
      "camera-to-world R = Rx(omega) Ry(phi) Rz(kappa), camera +X right, +Y up, +Z backward\n"
      "label,x,y,z,omega,phi,kappa\n";
  for (int index : shots) {
    const ir::Shot& shot = scene.shots.at(index);
    const ir::Vec3 centre = shot.object_from_camera.topRightCorner<3, 1>();
    const ir::Vec3 angles = omega_phi_kappa(camera_from_object(shot).topLeftCorner<3, 3>());
    text += fmt::format("{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n",
                        image_file_name(scene.camera, shot), centre.x(), centre.y(), centre.z(),
                        degrees(angles.x()), degrees(angles.y()), degrees(angles.z()));
  }
  return write_file_atomically(path, text, error);
}

}  // namespace rigc::run
