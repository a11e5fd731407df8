#include "raster/shadow_map_cache.h"

#include "raster/shadow_map.h"

namespace rigc::raster {

ShadowMapCache::ShadowMapCache() = default;
ShadowMapCache::~ShadowMapCache() = default;

std::shared_ptr<const FrameShadowMaps> ShadowMapCache::maps(const ir::Scene& scene,
                                                            const scene::StudioScene& studio,
                                                            double turntable_angle_rad, int size) {
  std::lock_guard lock(mutex_);
  for (const Entry& entry : entries_) {
    if (entry.studio == &studio && entry.angle == turntable_angle_rad && entry.size == size) {
      return entry.maps;
    }
  }
  const ir::Mat4 world_from_object = ir::world_from_object(scene, turntable_angle_rad);
  const Matrix3f object_rot = world_from_object.block<3, 3>(0, 0).cast<float>();
  const Vector3f object_t = world_from_object.block<3, 1>(0, 3).cast<float>();
  auto maps = std::make_shared<const FrameShadowMaps>(scene, studio, object_rot, object_t, size);
  ++builds_;
  entries_.push_front({&studio, turntable_angle_rad, size, maps});
  if (entries_.size() > kEntries) entries_.pop_back();
  return maps;
}

}  // namespace rigc::raster
