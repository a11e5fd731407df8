// Internal to the rasterizer: shadow maps, one per light, over the object at the frame's
// turntable angle and the turntable. Built here (shadow_map.cpp); looked up per shaded point by
// ShadowMap::visibility (shadow_visibility.h, inline where the shading is).
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

#include "ir/ir.h"
#include "raster/raster_common.h"
#include "scene/studio_scene.h"

namespace rigc::raster {

// A depth map from a light, over the shadow casters (object and turntable).
struct ShadowMap {
  bool orthographic = false;
  Matrix3f light_from_world = Matrix3f::Identity();  // rows: right, down, forward
  Vector3f origin = Vector3f::Zero();                // light position (or ortho centre)
  float focal = 1;          // perspective: pixels per unit of x/z; ortho: pixels per meter
  float texel_m_per_z = 0;  // world size of a texel at unit distance (perspective)
  float texel_m = 0;        // world size of a texel (orthographic)
  int size = 0;
  float softness_texels_per_m = 0;  // area lights: penumbra growth
  float light_size_m = 0;
  std::vector<float> depth;  // light-space z, +inf where empty
  // An area light's map: its shadows are soft (a cone rule, a blocker search, a penumbra filter),
  // and only its map keeps the reach map below.
  bool soft() const { return light_size_m > 0 && !orthographic; }
  // Per block of kBlock x kBlock texels (row-major, blocks_per_row a row), the nearest depth in
  // the 5 x 5 blocks around it: all that a tap 24 texels or less from a texel of the middle
  // block can read, in a map small enough to stay in cache.
  static constexpr int kBlock = 16;
  int blocks_per_row = 0;
  std::vector<float> reach_nearest;
  // Coarser maps for penumbrae wider than the taps' reach of 24 texels (a softbox's shadow cast
  // from far above the receiver spans hundreds): level k (coarse[k - 1]) holds, per texel, the
  // nearest depth of the 2^k x 2^k texels of `depth` under it, and its own reach map over blocks
  // of kBlock of its texels. A tap at level k reads the texel of `depth` it falls on, shifted
  // right by k; the search and the filter run at the level where their radius spans 24 texels.
  struct Level {
    int size = 0;
    std::vector<float> depth;
    // The fraction of those texels that hold a caster: a penumbra filter weighs a coarse texel's
    // block by it, or a blocker would grow by up to a coarse texel all round (a ball hiding a
    // sixth of a softbox would hide a quarter).
    std::vector<float> coverage;
    int blocks_per_row = 0;
    std::vector<float> reach_nearest;
  };
  std::vector<Level> coarse;
  float nearest_depth = std::numeric_limits<float>::infinity();  // over the whole map
  // The beyond-the-map's-texels part of the lit test, worked out per block: entry
  // kLevelSlots * block + J is the receiver depth below which the reach maps of levels 1 to J
  // around `block` (of level 0) hold nothing that can hide the light (see visibility).
  static constexpr int kLevelSlots = 8;
  std::vector<float> clear_below;
  // The smallest penumbra filter's radius, in texels; a margin of the cone rule (see visibility).
  static constexpr float kSmallestFilter = 1.5f;
  // An area light's half-diagonal over a texel's angle: the cone rule's constant.
  float cone() const { return focal * light_size_m * 0.70710678f; }

  // Fraction of light reaching a world point with geometric normal `normal`, which faces the
  // light at cos_theta.
  inline float visibility(const Vector3f& world, const Vector3f& normal, float cos_theta) const;
};

// The shadow maps of one frame, one per light (in the scene's order). Their buffers go back to
// the pool for the next frame's maps when the frame is done with them.
class FrameShadowMaps {
 public:
  // Maps over the object (turned by object_rot, object_t) and the turntable, `size` texels a side.
  FrameShadowMaps(const ir::Scene& scene, const scene::StudioScene& studio,
                  const Matrix3f& object_rot, const Vector3f& object_t, int size);
  ~FrameShadowMaps();
  FrameShadowMaps(const FrameShadowMaps&) = delete;
  FrameShadowMaps& operator=(const FrameShadowMaps&) = delete;

  const ShadowMap& operator[](std::size_t light) const { return maps_[light]; }

 private:
  std::vector<ShadowMap> maps_;
};

}  // namespace rigc::raster
