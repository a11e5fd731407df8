#include "run/bundler.h"

#include <fmt/format.h>

#include <cmath>

#include "io/atomic_file.h"
#include "run/colmap_text.h"

namespace rigc::run {

std::string bundler_camera_problem(const ir::Camera& camera, double scale) {
  constexpr double kMostFocalDifference = 0.005;  // of fx
  constexpr double kMostPrincipalOffset_px = 0.01;
  const auto out = output_camera(camera, scale, nullptr);
  if (!out) return {};
  if (std::abs(out->fy - out->fx) > kMostFocalDifference * out->fx) {
    return fmt::format("Bundler's cameras have one focal length, this one fx {:g} and fy {:g} px",
                       out->fx, out->fy);
  }
  if (std::abs(out->cx - out->width / 2.0) > kMostPrincipalOffset_px ||
      std::abs(out->cy - out->height / 2.0) > kMostPrincipalOffset_px) {
    return fmt::format(
        "Bundler's cameras have their principal point at the image centre ({:g}, "
        "{:g}), this one at ({:g}, {:g})",
        out->width / 2.0, out->height / 2.0, out->cx, out->cy);
  }
  return {};
}

bool write_bundler(const std::filesystem::path& out_path, const std::filesystem::path& list_path,
                   const ir::Scene& scene, const std::vector<int>& shots, double scale,
                   const GroundTruthPoints& points, std::string* error) {
  const auto camera = output_camera(scene.camera, scale, error);
  if (!camera) return false;
  const Eigen::Matrix3d flip = Eigen::Vector3d(1, -1, -1).asDiagonal();
  std::string out = fmt::format("# Bundle file v0.3\n{} {}\n", shots.size(), points.points.size());
  std::string list;
  for (int index : shots) {
    const ir::Shot& shot = scene.shots.at(index);
    const ir::Mat4 pose = camera_from_object(shot);
    const Eigen::Matrix3d r = flip * pose.topLeftCorner<3, 3>();
    const ir::Vec3 t = flip * pose.topRightCorner<3, 1>();
    out += fmt::format("{:.9g} {:.9g} {:.9g}\n", camera->fx, camera->distortion.k1,
                       camera->distortion.k2);
    for (int row = 0; row < 3; ++row) {
      out += fmt::format("{:.12g} {:.12g} {:.12g}\n", r(row, 0), r(row, 1), r(row, 2));
    }
    out += fmt::format("{:.12g} {:.12g} {:.12g}\n", t.x(), t.y(), t.z());
    list += image_relative_path(scene.camera, shot) + "\n";
  }
  for (const GroundTruthPoint& p : points.points) {
    out += fmt::format("{:.9g} {:.9g} {:.9g}\n{} {} {}\n{}", p.position.x(), p.position.y(),
                       p.position.z(), p.rgb[0], p.rgb[1], p.rgb[2], p.track.size());
    for (const GroundTruthObservation& o : p.track) {
      out += fmt::format(" {} {} {:.3f} {:.3f}", o.shot, o.point2d, o.x - camera->width / 2.0,
                         camera->height / 2.0 - o.y);
    }
    out += '\n';
  }
  return write_file_atomically(out_path, out, error) &&
         write_file_atomically(list_path, list, error);
}

}  // namespace rigc::run
