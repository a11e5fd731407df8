// Shadow maps kept across frames: while the live view's camera moves, the lights, the turntable
// and the object's angle stay, and so do their shadow maps.
#pragma once

#include <deque>
#include <memory>
#include <mutex>

#include "ir/ir.h"
#include "scene/studio_scene.h"

namespace rigc::raster {

class FrameShadowMaps;

// One cache serves one scene's lights and studio: whoever changes them makes a new cache.
class ShadowMapCache {
 public:
  ShadowMapCache();
  ~ShadowMapCache();
  ShadowMapCache(const ShadowMapCache&) = delete;
  ShadowMapCache& operator=(const ShadowMapCache&) = delete;

  // The maps of the scene's lights with the object at `turntable_angle_rad`, `size` texels a
  // side: kept ones when an earlier call asked for the same studio, angle and size.
  std::shared_ptr<const FrameShadowMaps> maps(const ir::Scene& scene,
                                              const scene::StudioScene& studio,
                                              double turntable_angle_rad, int size);
  int builds() const { return builds_; }  // maps built, not kept

 private:
  struct Entry {
    const scene::StudioScene* studio = nullptr;
    double angle = 0;
    int size = 0;
    std::shared_ptr<const FrameShadowMaps> maps;
  };
  // The live view's two sizes (moving and at rest).
  static constexpr size_t kEntries = 2;
  std::mutex mutex_;
  std::deque<Entry> entries_;  // newest first
  int builds_ = 0;
};

}  // namespace rigc::raster
