#include "scene/motion_blur.h"

#include <algorithm>
#include <cmath>

#include "dslr/exposure.h"

namespace rigc::scene {

int motion_blur_subframes(const ir::Scene& scene, const StudioScene& studio, const ir::Shot& shot,
                          double scale) {
  const ir::Camera& camera = scene.camera;
  if (!camera.effects.motion_blur || shot.turntable_velocity_rad_s == 0) return 1;
  // The fastest object point: the far rim of its bounding sphere, at its nearest depth.
  const double radius = studio.object_center.head<2>().norm() + studio.object_radius;
  const ir::Vec3 center_world =
      (ir::world_from_object(scene, shot.turntable_angle_rad) * studio.object_center.homogeneous())
          .head<3>();
  const ir::Vec3 eye = shot.world_from_camera.block<3, 1>(0, 3);
  const double depth = std::max(0.05, (center_world - eye).norm() - studio.object_radius);
  const double blur_px =
      dslr::motion_blur_length_px(camera, scale, shot.turntable_velocity_rad_s, radius, depth);
  // About one sub-frame per pixel of travel keeps the streak continuous.
  return std::clamp(static_cast<int>(std::ceil(blur_px)) + 1, 1, 48);
}

}  // namespace rigc::scene
