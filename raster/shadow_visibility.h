// Internal to the rasterizer: ShadowMap::visibility, the shadow lookup of one shaded point. Inline
// here so that the shading loop, which calls it per light for about a million points a frame,
// keeps it inlined.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <type_traits>

#include "raster/shadow_map.h"

namespace rigc::raster {
namespace shadow_taps {

// Fixed tap discs, in disc radii: deterministic, so the same scene gives the same pixels. Taps
// are looked up eight at a time. The blocker search and the filter of a hard edge take 16; the
// filter of an area light's penumbra 64, since its light level moves in steps of one tap: 16
// left 17 levels, bands a few pixels wide across a wide penumbra, with the map's texel stairs
// along each.
struct TapGroup {
  Float8 u, v, distance;  // eight taps, and their distance from the centre
};
inline constexpr TapGroup kSearch[2] = {
    {{-0.94f, 0.95f, -0.09f, 0.34f, -0.92f, -0.81f, -0.38f, 0.97f},
     {-0.40f, -0.77f, -0.93f, 0.29f, 0.46f, -0.88f, 0.28f, 0.76f},
     {1.0216f, 1.2229f, 0.9343f, 0.4469f, 1.0286f, 1.1960f, 0.4720f, 1.2323f}},
    {{0.44f, 0.54f, -0.26f, -0.10f, 0.79f, -0.62f, 0.20f, -0.50f},
     {-0.98f, 0.89f, -0.60f, 0.89f, 0.19f, 0.99f, -0.35f, -0.12f},
     {1.0742f, 1.0410f, 0.6539f, 0.8956f, 0.8125f, 1.1681f, 0.4031f, 0.5142f}}};

// A Vogel spiral of 8 x Groups taps: tap k at radius √((k + ½) / n), turned by the golden
// angle, fills the disc evenly with no two taps on one line through it.
template <std::size_t Groups>
std::array<TapGroup, Groups> spiral() {
  constexpr int n = 8 * Groups;
  std::array<TapGroup, Groups> groups{};
  for (int k = 0; k < n; ++k) {
    const float r = std::sqrt((k + 0.5f) / n), angle = k * 2.39996323f;
    groups[k / 8].u[k % 8] = r * std::cos(angle);
    groups[k / 8].v[k % 8] = r * std::sin(angle);
    groups[k / 8].distance[k % 8] = r;
  }
  return groups;
}

// An area light's penumbra filter.
inline const std::array<TapGroup, 8>& filter() {
  static const std::array<TapGroup, 8> taps = spiral<8>();
  return taps;
}

// The search beyond the map's own texels: its disc is wider than the filters it leads to, and
// 16 taps can miss a blocker that fills a sixth of it (the penumbra's outer part then ends in a
// step from a tenth of the light hidden to none), so it takes 32.
inline const std::array<TapGroup, 4>& wide_search() {
  static const std::array<TapGroup, 4> taps = spiral<4>();
  return taps;
}

}  // namespace shadow_taps

// The lookups of one receiver point in one shadow map, at map coordinates (u, v).
class ShadowLookup {
 public:
  using TapGroup = shadow_taps::TapGroup;

  // `local`: the point in the light's frame; `texel`: a texel's world size there; `normal`: the
  // geometric normal, which faces the light at cos_theta.
  ShadowLookup(const ShadowMap& map, const Vector3f& local, const Vector3f& normal, float u,
               float v, float texel, float cos_theta)
      : map_(map),
        local_(local),
        normal_(normal),
        u_(u),
        v_(v),
        texel_(texel),
        size_(map.size),
        tan_theta_(std::sqrt(std::max(0.0f, 1 - cos_theta * cos_theta)) /
                   std::max(cos_theta, 0.15f)),
        receiver_(local.z() - (texel * (1.5f + 2.0f * tan_theta_) + 0.002f)),
        interior_(u >= 25 && v >= 25 && u < size_ - 25 && v < size_ - 25),
        z_r_(local.z()),
        cone_(map.cone()),
        area_light_(map.soft()) {}

  // An area light: percentage-closer soft shadows, the penumbra growing with the receiver-blocker
  // distance. `outside`: (u, v) lies off the map.
  float soft_visibility(bool outside);

  // Other lights: a hard edge, smoothed over the smallest filter.
  float hard_visibility() {
    follow_plane();
    int lit = 0;
    for (const TapGroup& taps : shadow_taps::kSearch) {
      lit += 8 - simd::count(blocks8(disc8(taps, kSmallestFilter, 0), taps, kSmallestFilter, 0));
    }
    return static_cast<float>(lit) / 16;
  }

 private:
  static constexpr float kSmallestFilter = ShadowMap::kSmallestFilter;
  static constexpr int kBlock = ShadowMap::kBlock;
  // Taps reach at most kReach texels of their level from (u, v): away from the map's border a
  // level-0 disc needs no clamping.
  static constexpr float kReach = 24;

  // The receiver's own plane, as light-space depth per texel along u and v: each tap is compared
  // with the plane's depth there rather than the point's. Otherwise a surface sloping away from
  // the light finds "blockers" in its own texels a few texels off (the taps reach 24), and most
  // lit points would pay for the whole soft-shadow search only to come out fully lit. Worked out
  // only once taps are to be compared: most points are settled lit before that.
  // slope_per_texel_: see receiver_at.
  void follow_plane() {
    if (plane_followed_) return;
    plane_followed_ = true;
    const Vector3f m = map_.light_from_world * normal_;
    // Orthographic: z = L.z - (m.x dx + m.y dy) / m.z with dx = du / focal. Perspective, along the
    // ray through texel (u + du, v + dv), to first order: L.z - L.z^2 (m.x du + m.y dv) / (focal
    // m.L). The plane lies deeper than that by the second-order term, which errs towards lit and
    // stays within the bias up to the slope limit below (24 texels out: 1.6 mm at tan 6.6 on the
    // paper scene's 2048 map, against a 2 mm bias).
    const float along = map_.orthographic ? m.z() * map_.focal
                                          : m.dot(local_) * map_.focal / (local_.z() * local_.z());
    // Steeper than kMaxSlope (light grazing the surface) the plane is not followed: the bias's
    // slope term covers those.
    constexpr float kMaxSlope = 6.6f;
    const float limit = texel_ * kMaxSlope;
    if (std::abs(along) * limit > std::max(std::abs(m.x()), std::abs(m.y()))) {
      slope_u_ = -m.x() / along;
      slope_v_ = -m.y() / along;
    }
    slope_per_texel_ =
        texel_ * 1.5f + (slope_u_ != 0 || slope_v_ != 0 ? std::abs(slope_u_) + std::abs(slope_v_)
                                                        : texel_ * 2.0f * tan_theta_);
  }

  // The depth at (su, sv) of level 0.
  float depth_at(float su, float sv) const {
    int iu = static_cast<int>(su), iv = static_cast<int>(sv);
    if (!interior_) {
      iu = std::clamp(iu, 0, size_ - 1);
      iv = std::clamp(iv, 0, size_ - 1);
    }
    return map_.depth[static_cast<size_t>(iv) * size_ + iu];
  }

  // Depths at a group's eight taps scaled by `radius` (texels of level 0) around (u, v), read
  // at `level`.
  Float8 disc8(const TapGroup& taps, float radius, int level, Float8* held = nullptr) const {
    const Float8 su = u_ + taps.u * radius, sv = v_ + taps.v * radius;
    Int8 iu = __builtin_convertvector(su, Int8), iv = __builtin_convertvector(sv, Int8);
    if (level == 0 && interior_) return simd::gather(map_.depth.data(), iv * size_ + iu);
    // Off the map there is nothing: the map's frustum holds every caster with a margin, so its
    // edge texels are empty too, except where a caster leaves the frustum (the turntable's
    // stand), which the taps would otherwise repeat outwards in streaks.
    const Int8 zero = {}, last = zero + (size_ - 1);
    const Int8 off_map = (iu < zero) | (iu > last) | (iv < zero) | (iv > last);
    iu = iu < zero ? zero : (iu > last ? last : iu);
    iv = iv < zero ? zero : (iv > last ? last : iv);
    if (level == 0) {
      const Float8 z = simd::gather(map_.depth.data(), iv * size_ + iu);
      return off_map ? Float8{} + std::numeric_limits<float>::infinity() : z;
    }
    // A coarser level: its depths, and (into `held`, when asked) how much of each texel holds a
    // caster.
    const ShadowMap::Level& coarser = map_.coarse[level - 1];
    const Int8 at = (iv >> level) * coarser.size + (iu >> level);
    if (held) *held = off_map ? Float8{} : simd::gather(coarser.coverage.data(), at);
    const Float8 z = simd::gather(coarser.depth.data(), at);
    return off_map ? Float8{} + std::numeric_limits<float>::infinity() : z;
  }

  // The receiver's depth less the bias under a group's eight taps. A texel of level k holds the
  // nearest of 2^k x 2^k: on the receiver's own plane up to 2^k - 1 texels' slope nearer (the
  // plane's own slope where it is followed, the bias's slope term where not), so the bias grows
  // by that much and no more. Growing the whole bias with 2^k would make a grazing receiver's
  // bias jump by centimetres where the filter moves to the next level: on a turntable top behind
  // a box, a hard line where the box's low part stops counting. (After follow_plane.)
  Float8 receiver_at(const TapGroup& taps, float radius, int level) const {
    const float coarser_bias = static_cast<float>((1 << level) - 1) * slope_per_texel_;
    return receiver_ - coarser_bias + (taps.u * slope_u_ + taps.v * slope_v_) * radius;
  }

  // A texel d texels from the point, at depth z, can hide part of an area light only from
  // inside the cone from the point to the light: d <= C (1/z - 1/z_r), C the light's
  // half-diagonal over a texel's angle, widened by the smallest filter's radius (which also
  // covers the lookup's truncation). The statue's own relief a few millimetres above its
  // surface, anywhere in a 24-texel disc, is no blocker; only within a texel or two of the point
  // can it hide the light. Where the cone is narrower than the smallest filter (a small light, or
  // a blocker just above the surface at a contact), that filter's taps must all count: it
  // smooths the map's texel stairs, and with a 1-texel margin its outer taps would come out
  // lit, opening a lit gap between a box's foot and its shadow. A coarser level's texel may hold a
  // depth from anywhere in its 2^k texels: the margin grows alike.
  Int8 can_hide(const Float8& z, const Float8& d, float margin) const {
    return (d - margin) * z * z_r_ <= cone_ * (z_r_ - z);
  }

  // Eight taps at once: z below the receiver's plane and, for an area light, inside the cone.
  // (A point light's cone is a line: its taps only smooth a hard edge.)
  Int8 blocks8(const Float8& z, const TapGroup& taps, float radius, int level) const {
    const Int8 below = z < receiver_at(taps, radius, level);
    if (!area_light_) return below;
    return below & can_hide(z, taps.distance * radius, kSmallestFilter * (1 << level));
  }

  // The level at which `radius` (texels of level 0) spans kReach texels or less.
  int level_for(float radius) const {
    int level = 0;
    while (level < most_coarse_ && radius > kReach * static_cast<float>(1 << level)) ++level;
    return level;
  }

  // The penumbra filter over a disc of `radius`, once the search has found blockers.
  float filter(float radius) const {
    const int level = level_for(radius);
    if (level == 0) {
      int lit = 0;
      for (const TapGroup& taps : shadow_taps::filter()) {
        lit += 8 - simd::count(blocks8(disc8(taps, radius, 0), taps, radius, 0));
      }
      return static_cast<float>(lit) / 64;
    }
    Float8 hidden = {};
    for (const TapGroup& taps : shadow_taps::filter()) {
      Float8 held;
      const Float8 z = disc8(taps, radius, level, &held);
      hidden += blocks8(z, taps, radius, level) ? held : Float8{};
    }
    return 1 - simd::sum(hidden) / 64;
  }

  // Blockers among `tap_groups` over `radius` at `level`: their count and mean depth.
  int search_blockers(std::span<const TapGroup> tap_groups, float radius, int level,
                      float& mean_depth) const {
    int blockers = 0;
    Float8 blocker_sum = {};
    for (const TapGroup& taps : tap_groups) {
      const Float8 z = disc8(taps, radius, level);
      const Int8 blocks = blocks8(z, taps, radius, level);
      blockers += simd::count(blocks);
      blocker_sum += blocks ? z : Float8{};
    }
    mean_depth = blockers > 0 ? simd::sum(blocker_sum) / static_cast<float>(blockers) : 0;
    return blockers;
  }

  // The filter's radius: the light seen from the receiver through the blockers' depth, as a
  // disc of the light's area (a square of side L: radius L / √π), so that a blocker wholly
  // inside hides the fraction of the light that it hides from the receiver.
  float penumbra_texels(float blocker) const {
    constexpr float kDiscOfSquare = 0.56418958f;  // 1 / √π
    const float penumbra_m =
        kDiscOfSquare * map_.light_size_m * (receiver_ - blocker) / std::max(blocker, 0.01f);
    return std::clamp(penumbra_m / texel_, kSmallestFilter, widest_);
  }

  // Whether nothing a reach map holds can hide the light from `distance` texels away, or
  // more: `nearest` is beyond the depth that can_hide allows there (solved for z; a margin
  // for rounding).
  bool clear_from(float nearest, float distance) const {
    return nearest * (cone_ + (distance - kSmallestFilter) * z_r_) > z_r_ * cone_ * (1 + 1e-5f);
  }

  // Whether the coarser levels' reach maps around the point hold nothing that could hide the
  // light (a point inside the map reads the per-block bound).
  bool far_clear(bool outside, float outside_by, int inside_u, int inside_v, int reach_block,
                 int search_level) const;

  const ShadowMap& map_;
  const Vector3f local_, normal_;
  const float u_, v_, texel_;
  const int size_;
  const float tan_theta_;
  const float receiver_;  // the point's light-space depth less the bias
  const bool interior_;   // (u, v) at least kReach + 1 texels inside the map
  const float z_r_;       // the receiver's light-space depth
  const float cone_;
  const bool area_light_;
  float slope_u_ = 0, slope_v_ = 0, slope_per_texel_ = 0;  // see follow_plane
  bool plane_followed_ = false;
  // The soft search (set by soft_visibility).
  int most_coarse_ = 0;
  float widest_ = 0;
};

inline bool ShadowLookup::far_clear(bool outside, float outside_by, int inside_u, int inside_v,
                                    int reach_block, int search_level) const {
  // Level k's reach map covers the 5 x 5 of its blocks (16 texels of level k) around the
  // point's, and anything outside level k - 1's lies 2 of its blocks away or more. Inside the
  // map, the per-block bound holds these tests already made.
  bool clear =
      outside ? true : z_r_ < map_.clear_below[reach_block * ShadowMap::kLevelSlots + search_level];
  for (int level = 1; outside && level <= search_level && clear; ++level) {
    const ShadowMap::Level& coarser = map_.coarse[level - 1];
    const int block =
        (inside_v >> (4 + level)) * coarser.blocks_per_row + (inside_u >> (4 + level));
    clear = clear_from(coarser.reach_nearest[block],
                       std::max(static_cast<float>(16 << level), outside_by));
  }
  static_assert(kBlock == 16);
  return clear;
}

inline float ShadowLookup::soft_visibility(bool outside) {
  // The search covers where a blocker could hide part of the light; it starts in the map's
  // own texels, within kReach of the point, and goes on at the level where the rest fits.
  most_coarse_ = static_cast<int>(map_.coarse.size());
  widest_ = kReach * static_cast<float>(1 << most_coarse_);
  // No farther than the map's nearest caster could hide any of the light from (can_hide
  // solved for d): on the object itself that is a few centimetres, on the backdrop behind it
  // tens.
  const float nearest_depth = map_.nearest_depth;
  const float cone_of_nearest =
      nearest_depth < z_r_ ? cone_ * (z_r_ - nearest_depth) / (nearest_depth * z_r_) : 0.0f;
  const float full_search =
      std::clamp(std::min(map_.light_size_m / std::max(local_.z(), 0.05f) * map_.focal * 0.5f,
                          cone_of_nearest + kSmallestFilter),
                 2.0f, widest_);
  const float search = std::min(full_search, kReach);
  // Most points are plainly lit, and one test settles the map's own texels: the centre tap
  // is lit, and nothing within the taps' reach (the 5 x 5 blocks around the point's) is near
  // enough the light to hide any of it from the search radius's distance. Only blockers lower
  // still, inside the radius and missed by the centre tap, are left lit. (Four far taps at the
  // search area's corners would settle many more, but miss blockers between them and the
  // centre: near a box's foot the penumbra's outer edge comes out as a step.) A point outside
  // the map is judged at the nearest texel inside: nothing in the map is nearer the point than
  // that texel is (a square is convex), and all of it is `outside_by` away or more.
  const float outside_by = std::max(
      {-u_, -v_, u_ - static_cast<float>(size_ - 1), v_ - static_cast<float>(size_ - 1), 0.0f});
  if (outside_by > full_search) return 1;
  const int inside_u = std::clamp(static_cast<int>(u_), 0, size_ - 1);
  const int inside_v = std::clamp(static_cast<int>(v_), 0, size_ - 1);
  const int reach_block = (inside_v / kBlock) * map_.blocks_per_row + inside_u / kBlock;
  const bool near_clear = depth_at(u_, v_) >= receiver_ &&
                          clear_from(map_.reach_nearest[reach_block], std::max(search, outside_by));
  if (!near_clear) {
    follow_plane();
    float blocker = 0;
    const int blockers = search_blockers(shadow_taps::kSearch, search, 0, blocker);
    if (blockers > 0) {
      const float radius = penumbra_texels(blocker);
      // The whole search area blocks, and the penumbra is no wider: umbra.
      if (blockers == 16 && radius <= kReach) return 0;
      return filter(radius);
    }
  }
  // Farther out.
  const int search_level = level_for(full_search);
  if (far_clear(outside, outside_by, inside_u, inside_v, reach_block, search_level)) return 1;
  follow_plane();
  float blocker = 0;
  if (search_blockers(shadow_taps::wide_search(), full_search, search_level, blocker) == 0) {
    return 1;
  }
  return filter(penumbra_texels(blocker));
}

inline float ShadowMap::visibility(const Vector3f& world, const Vector3f& normal,
                                   float cos_theta) const {
  if (depth.empty()) return 1;
  const Vector3f local = light_from_world * (world - origin);
  float u, v, texel;
  if (orthographic) {
    u = local.x() * focal + size / 2.0f;
    v = local.y() * focal + size / 2.0f;
    texel = texel_m;
  } else {
    if (local.z() <= kNear) return 1;
    u = local.x() / local.z() * focal + size / 2.0f;
    v = local.y() / local.z() * focal + size / 2.0f;
    texel = texel_m_per_z * local.z();
  }
  // Outside the map nothing casts a hard shadow; an area light's penumbra reaches further (the
  // map covers the casters, a wide penumbra the receivers around them too).
  const bool outside = u < 0 || v < 0 || u >= size || v >= size;
  if (outside && !soft()) return 1;
  ShadowLookup lookup(*this, local, normal, u, v, texel, cos_theta);
  return soft() ? lookup.soft_visibility(outside) : lookup.hard_visibility();
}

}  // namespace rigc::raster
