// The ground-truth cameras as a reference CSV, as photogrammetry tools import camera positions
// for georeferenced captures (Metashape's "Import Reference", RealityCapture's flight log).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "ir/ir.h"

namespace rigc::run {

// Omega, phi, kappa (radians) of a camera_from_world rotation: the photogrammetric angles of the
// camera-to-world rotation R = Rx(omega) Ry(phi) Rz(kappa) of a camera whose axes are +X right,
// +Y up, +Z backward (Metashape's and RealityCapture's convention).
ir::Vec3 omega_phi_kappa(const Eigen::Matrix3d& camera_from_world);
// The inverse: camera_from_world (OpenCV axes) of omega, phi, kappa.
Eigen::Matrix3d rotation_from_omega_phi_kappa(const ir::Vec3& angles);

// cameras.csv: a "#" comment naming the frame and conventions, a header line
// "label,x,y,z,omega,phi,kappa", and one line per shot: the image file name, the camera centre in
// the object frame (meters) and omega, phi, kappa in degrees. Atomic; false with `error`.
bool write_camera_csv(const std::filesystem::path& path, const ir::Scene& scene,
                      const std::vector<int>& shots, std::string* error);

}  // namespace rigc::run
