#include "ir/ir.h"

namespace rigc::ir {

Mat4 world_from_object(const Scene& scene, double turntable_angle_rad) {
  Mat4 world_from_object = Mat4::Identity();
  world_from_object.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(turntable_angle_rad, Vec3::UnitZ()).toRotationMatrix();
  world_from_object.topRightCorner<3, 1>() = Vec3(0, 0, scene.studio.turntable.height_m);
  return world_from_object;
}

std::vector<Eigen::Vector3f> object_frame_positions(const Object& object) {
  std::vector<Eigen::Vector3f> positions;
  positions.reserve(object.mesh.positions.size());
  for (const auto& p : object.mesh.positions) {
    const Vec3 q = object.object_from_mesh.topLeftCorner<3, 3>() * p.cast<double>() +
                   object.object_from_mesh.topRightCorner<3, 1>();
    positions.push_back(q.cast<float>());
  }
  return positions;
}

}  // namespace rigc::ir
