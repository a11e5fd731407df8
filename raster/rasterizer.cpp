#include "raster/rasterizer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <span>
#include <type_traits>
#include <utility>

#include "dslr/buffer_pool.h"
#include "dslr/optics.h"
#include "dslr/simd.h"

namespace rigc::raster {
namespace {

using Eigen::Matrix3f;
using Eigen::Vector2f;
using Eigen::Vector3f;
using Clock = std::chrono::steady_clock;

constexpr int kTileSize = 32;
constexpr int kSamples = 4;
// Rotated-grid sample offsets inside a pixel: good edge anti-aliasing for four samples.
constexpr float kSampleX[kSamples] = {0.375f, 0.875f, 0.125f, 0.625f};
constexpr float kSampleY[kSamples] = {0.125f, 0.375f, 0.625f, 0.875f};
constexpr float kNear = 0.01f;
// Blender's photometric convention: 1 W of light is 683 lm at 555 nm.
constexpr float kLumensPerWatt = 683.0f;
constexpr float kPi = std::numbers::pi_v<float>;
// Shading normals of a 2 x 2 quad within this angle (2 degrees) of their mean share one sum of
// the lights.
constexpr float kQuadNormalCos = 0.99939f;
// A 4 x 4 block of the object whose corner normals are within this angle (8 degrees) of each
// other has its lighting interpolated bilinearly from the corners. Interpolation follows the
// first-order change that a quad's single sum ignores, so the bound can be looser.
constexpr float kBlockNormalCos = 0.9903f;
// A block whose corner normals spread further, up to 25 degrees (a scanned statue's small bumps),
// is interpolated too when the lights summed at its centre match the corners' mean within 1 %
// for the block's albedo: the bend that matters is the light's, not the normal's. Beyond 25
// degrees, or failing the check, it is shaded in quads.
constexpr float kBlockBumpyNormalCos = 0.9063f;
constexpr float kBlockLightTolerance = 0.01f;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// A triangle after clipping and projection, 64 bytes: a million of them are set up per frame,
// so their size is memory traffic. Attributes are looked up in the source triangle through the
// barycentric coordinates each corner has there (identity unless the triangle was clipped).
struct ScreenTriangle {
  // Planes in pixel coordinates, value = a·x + b·y + c: the barycentrics w0, w1 and 1/z.
  std::array<float, 3> w0_plane, w1_plane, inv_z_plane;
  std::array<float, 3> inv_z;  // 1 / camera z at the corners
  // Pixels the bounding box touches on the canvas, inclusive.
  std::uint16_t x0, y0, x1, y1;
  std::int32_t source;   // triangle index; object triangles first, then studio
  std::int32_t clipped;  // -1, or index of the corners' source barycentrics in ScreenSetup
};
static_assert(sizeof(ScreenTriangle) == 64);

// The planes of a screen triangle with corners `screen`, given 1 / (twice its signed area).
void compute_planes(ScreenTriangle& t, const std::array<Vector2f, 3>& screen, float inv_area) {
  auto edge_plane = [&](const Vector2f& a, const Vector2f& b) {
    return std::array<float, 3>{-(b.y() - a.y()) * inv_area, (b.x() - a.x()) * inv_area,
                                ((b.y() - a.y()) * a.x() - (b.x() - a.x()) * a.y()) * inv_area};
  };
  t.w0_plane = edge_plane(screen[1], screen[2]);
  t.w1_plane = edge_plane(screen[2], screen[0]);
  // w2 = 1 - w0 - w1, so 1/z = iz2 + w0·(iz0 - iz2) + w1·(iz1 - iz2).
  const float d0 = t.inv_z[0] - t.inv_z[2], d1 = t.inv_z[1] - t.inv_z[2];
  for (int i = 0; i < 3; ++i) t.inv_z_plane[i] = t.w0_plane[i] * d0 + t.w1_plane[i] * d1;
  t.inv_z_plane[2] += t.inv_z[2];
}

struct FrameGeometry {
  const scene::Geometry* object;
  const scene::Geometry* studio;
  Matrix3f world_from_object_rot;
  Vector3f world_from_object_t;
  int object_triangles;
};

// Clips a camera-space triangle against z = kNear; emits 0, 1 or 2 triangles.
template <typename Emit>
void clip_near(const std::array<Vector3f, 3>& cam, Emit emit) {
  std::array<Vector3f, 4> out_p;
  std::array<Vector3f, 4> out_b;
  int count = 0;
  const Vector3f bary[3] = {Vector3f(1, 0, 0), Vector3f(0, 1, 0), Vector3f(0, 0, 1)};
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const bool in_i = cam[i].z() >= kNear, in_j = cam[j].z() >= kNear;
    if (in_i) {
      out_p[count] = cam[i];
      out_b[count++] = bary[i];
    }
    if (in_i != in_j) {
      const float t = (kNear - cam[i].z()) / (cam[j].z() - cam[i].z());
      out_p[count] = cam[i] + t * (cam[j] - cam[i]);
      out_b[count++] = bary[i] + t * (bary[j] - bary[i]);
    }
  }
  if (count < 3) return;
  emit(std::array<Vector3f, 3>{out_p[0], out_p[1], out_p[2]},
       std::array<Vector3f, 3>{out_b[0], out_b[1], out_b[2]});
  if (count == 4) {
    emit(std::array<Vector3f, 3>{out_p[0], out_p[2], out_p[3]},
         std::array<Vector3f, 3>{out_b[0], out_b[2], out_b[3]});
  }
}

inline float edge(const Vector2f& a, const Vector2f& b, float px, float py) {
  return (b.x() - a.x()) * (py - a.y()) - (b.y() - a.y()) * (px - a.x());
}

// Perspective-correct barycentrics of the screen triangle at (px, py), unclamped.
inline Vector3f screen_bary(const ScreenTriangle& t, float px, float py) {
  const float w0 = t.w0_plane[0] * px + t.w0_plane[1] * py + t.w0_plane[2];
  const float w1 = t.w1_plane[0] * px + t.w1_plane[1] * py + t.w1_plane[2];
  const float w2 = 1 - w0 - w1;
  Vector3f p(w0 * t.inv_z[0], w1 * t.inv_z[1], w2 * t.inv_z[2]);
  const float sum = p.sum();
  return sum != 0 ? Vector3f(p / sum) : Vector3f(1.0f / 3, 1.0f / 3, 1.0f / 3);
}

// Items (triangles) sorted into cells (tiles, bands): cell c holds
// items[start[c] .. start[c + 1]), in item order, so ties resolve as in a serial pass.
struct CellBins {
  std::vector<std::int32_t> start;
  std::vector<std::int32_t> items;
};

// cells_of(i, fn) calls fn(cell) for every cell item i touches. Counting per block of items and
// cell, then filling, both in parallel.
template <typename CellsOf>
CellBins bin_items(int item_count, int cell_count, const CellsOf& cells_of) {
  CellBins bins;
  const int blocks = std::clamp(item_count / 16384, 1, 64);
  auto block_begin = [&](int b) {
    return static_cast<int>(static_cast<std::int64_t>(item_count) * b / blocks);
  };
  std::vector<std::int32_t> cursor(static_cast<size_t>(blocks) * cell_count, 0);
  tbb::parallel_for(0, blocks, [&](int b) {
    std::int32_t* count = cursor.data() + static_cast<size_t>(b) * cell_count;
    for (int i = block_begin(b); i < block_begin(b + 1); ++i) {
      cells_of(i, [&](int cell) { ++count[cell]; });
    }
  });
  bins.start.resize(cell_count + 1);
  std::int32_t running = 0;
  for (int cell = 0; cell < cell_count; ++cell) {
    bins.start[cell] = running;
    for (int b = 0; b < blocks; ++b) {
      std::int32_t& slot = cursor[static_cast<size_t>(b) * cell_count + cell];
      const std::int32_t count = slot;
      slot = running;
      running += count;
    }
  }
  bins.start[cell_count] = running;
  bins.items.resize(running);
  tbb::parallel_for(0, blocks, [&](int b) {
    std::int32_t* next = cursor.data() + static_cast<size_t>(b) * cell_count;
    for (int i = block_begin(b); i < block_begin(b + 1); ++i) {
      cells_of(i, [&](int cell) { bins.items[next[cell]++] = i; });
    }
  });
  return bins;
}

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
    // sixth of a softbox hid a quarter).
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
  float visibility(const Vector3f& world, const Vector3f& normal, float cos_theta) const;
};

Matrix3f light_frame(const Vector3f& forward_in) {
  Vector3f forward = forward_in.normalized();
  Vector3f up = std::abs(forward.z()) > 0.99f ? Vector3f::UnitY() : Vector3f::UnitZ();
  Vector3f right = forward.cross(up).normalized();
  Vector3f down = forward.cross(right);
  Matrix3f m;
  m.row(0) = right;
  m.row(1) = down;
  m.row(2) = forward;
  return m;
}

float ShadowMap::visibility(const Vector3f& world, const Vector3f& normal, float cos_theta) const {
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
  const float tan_theta =
      std::sqrt(std::max(0.0f, 1 - cos_theta * cos_theta)) / std::max(cos_theta, 0.15f);
  const float bias = texel * (1.5f + 2.0f * tan_theta) + 0.002f;
  const float receiver = local.z() - bias;
  // The receiver's own plane, as light-space depth per texel along u and v: each tap is compared
  // with the plane's depth there rather than the point's. Otherwise a surface sloping away from
  // the light finds "blockers" in its own texels a few texels off (the taps reach 24), and most
  // lit points paid for the whole soft-shadow search only to come out fully lit.
  // Worked out only once taps are to be compared (follow_plane): most points are settled lit
  // before that. slope_per_texel: see receiver_at.
  float slope_u = 0, slope_v = 0, slope_per_texel = 0;
  bool plane_followed = false;
  auto follow_plane = [&] {
    if (plane_followed) return;
    plane_followed = true;
    const Vector3f m = light_from_world * normal;
    // Orthographic: z = L.z - (m.x dx + m.y dy) / m.z with dx = du / focal. Perspective, along the
    // ray through texel (u + du, v + dv), to first order: L.z - L.z^2 (m.x du + m.y dv) / (focal
    // m.L). The plane lies deeper than that by the second-order term, which errs towards lit and
    // stays within the bias up to the slope limit below (24 texels out: 1.6 mm at tan 6.6 on the
    // paper scene's 2048 map, against a 2 mm bias).
    const float along =
        orthographic ? m.z() * focal : m.dot(local) * focal / (local.z() * local.z());
    // Steeper than kMaxSlope (light grazing the surface) the plane is not followed: the bias's
    // slope term covers those, as it did for every point before.
    constexpr float kMaxSlope = 6.6f;
    const float limit = texel * kMaxSlope;
    if (std::abs(along) * limit > std::max(std::abs(m.x()), std::abs(m.y()))) {
      slope_u = -m.x() / along;
      slope_v = -m.y() / along;
    }
    slope_per_texel =
        texel * 1.5f + (slope_u != 0 || slope_v != 0 ? std::abs(slope_u) + std::abs(slope_v)
                                                     : texel * 2.0f * tan_theta);
  };
  // Taps reach at most kReach texels of their level from (u, v): away from the map's border a
  // level-0 disc needs no clamping.
  constexpr float kReach = 24;
  const bool interior = u >= 25 && v >= 25 && u < size - 25 && v < size - 25;
  auto lookup = [&](float su, float sv) {
    int iu = static_cast<int>(su), iv = static_cast<int>(sv);
    if (!interior) {
      iu = std::clamp(iu, 0, size - 1);
      iv = std::clamp(iv, 0, size - 1);
    }
    return depth[static_cast<size_t>(iv) * size + iu];
  };
  // Fixed tap discs, in disc radii: deterministic, so the same scene gives the same pixels. Taps
  // are looked up eight at a time. The blocker search and the filter of a hard edge take 16; the
  // filter of an area light's penumbra 64, since its light level moves in steps of one tap: 16
  // left 17 levels, bands a few pixels wide across a wide penumbra, with the map's texel stairs
  // along each.
  using Float8 = simd::F32x8;
  using Int8 = simd::I32x8;
  struct TapGroup {
    Float8 u, v, distance;  // eight taps, and their distance from the centre
  };
  static constexpr TapGroup kSearchTaps[2] = {
      {{-0.94f, 0.95f, -0.09f, 0.34f, -0.92f, -0.81f, -0.38f, 0.97f},
       {-0.40f, -0.77f, -0.93f, 0.29f, 0.46f, -0.88f, 0.28f, 0.76f},
       {1.0216f, 1.2229f, 0.9343f, 0.4469f, 1.0286f, 1.1960f, 0.4720f, 1.2323f}},
      {{0.44f, 0.54f, -0.26f, -0.10f, 0.79f, -0.62f, 0.20f, -0.50f},
       {-0.98f, 0.89f, -0.60f, 0.89f, 0.19f, 0.99f, -0.35f, -0.12f},
       {1.0742f, 1.0410f, 0.6539f, 0.8956f, 0.8125f, 1.1681f, 0.4031f, 0.5142f}}};
  // A Vogel spiral of 8 x Groups taps: tap k at radius √((k + ½) / n), turned by the golden
  // angle, fills the disc evenly with no two taps on one line through it.
  auto spiral = []<std::size_t Groups>(std::integral_constant<std::size_t, Groups>) {
    constexpr int n = 8 * Groups;
    std::array<TapGroup, Groups> groups{};
    for (int k = 0; k < n; ++k) {
      const float r = std::sqrt((k + 0.5f) / n), angle = k * 2.39996323f;
      groups[k / 8].u[k % 8] = r * std::cos(angle);
      groups[k / 8].v[k % 8] = r * std::sin(angle);
      groups[k / 8].distance[k % 8] = r;
    }
    return groups;
  };
  static const std::array<TapGroup, 8> filter_taps =
      spiral(std::integral_constant<std::size_t, 8>{});
  // The search beyond the map's own texels: its disc is wider than the filters it leads to, and
  // 16 taps missed a blocker that filled a sixth of it (the penumbra's outer part then ended in
  // a step from a tenth of the light hidden to none).
  static const std::array<TapGroup, 4> wide_search_taps =
      spiral(std::integral_constant<std::size_t, 4>{});
  // Depths at a group's eight taps scaled by `radius` (texels of level 0) around (u, v), read
  // at `level`.
  auto disc8 = [&](const TapGroup& taps, float radius, int level, Float8* held = nullptr) {
    const Float8 su = u + taps.u * radius, sv = v + taps.v * radius;
    Int8 iu = __builtin_convertvector(su, Int8), iv = __builtin_convertvector(sv, Int8);
    if (level == 0 && interior) return simd::gather(depth.data(), iv * size + iu);
    // Off the map there is nothing: the map's frustum holds every caster with a margin, so its
    // edge texels are empty too, except where a caster leaves the frustum (the turntable's
    // stand), which the taps would otherwise repeat outwards in streaks.
    const Int8 zero = {}, last = zero + (size - 1);
    const Int8 off_map = (iu < zero) | (iu > last) | (iv < zero) | (iv > last);
    iu = iu < zero ? zero : (iu > last ? last : iu);
    iv = iv < zero ? zero : (iv > last ? last : iv);
    if (level == 0) {
      const Float8 z = simd::gather(depth.data(), iv * size + iu);
      return off_map ? Float8{} + std::numeric_limits<float>::infinity() : z;
    }
    // A coarser level: its depths, and (into `held`, when asked) how much of each texel holds a
    // caster.
    const Level& coarser = coarse[level - 1];
    const Int8 at = (iv >> level) * coarser.size + (iu >> level);
    if (held) *held = off_map ? Float8{} : simd::gather(coarser.coverage.data(), at);
    const Float8 z = simd::gather(coarser.depth.data(), at);
    return off_map ? Float8{} + std::numeric_limits<float>::infinity() : z;
  };
  // The receiver's depth less the bias under a group's eight taps. A texel of level k holds the
  // nearest of 2^k x 2^k: on the receiver's own plane up to 2^k - 1 texels' slope nearer (the
  // plane's own slope where it is followed, the bias's slope term where not), so the bias grows
  // by that much and no more. Growing the whole bias with 2^k made a grazing receiver's bias jump
  // by centimetres where the filter moved to the next level: on a turntable top behind a box, a
  // hard line where the box's low part stopped counting. (After follow_plane.)
  auto receiver_at = [&](const TapGroup& taps, float radius, int level) {
    const float coarser_bias = static_cast<float>((1 << level) - 1) * slope_per_texel;
    return receiver - coarser_bias + (taps.u * slope_u + taps.v * slope_v) * radius;
  };
  // A texel d texels from the point, at depth z, can hide part of an area light only from
  // inside the cone from the point to the light: d <= C (1/z - 1/z_r), C the light's
  // half-diagonal over a texel's angle, widened by the smallest filter's radius (which also
  // covers the lookup's truncation). The statue's own relief a few millimetres above its
  // surface, anywhere in a 24-texel disc, counted as blockers before; only within a texel or two
  // of the point can it hide the light. Where the cone is narrower than the smallest filter (a
  // small light, or a blocker just above the surface at a contact), that filter's taps must all
  // count: it smooths the map's texel stairs, and with a 1-texel margin its outer taps came out
  // lit, opening a lit gap between a box's foot and its shadow. A coarser level's texel may
  // hold a depth from anywhere in its 2^k texels: the margin grows alike.
  const float z_r = local.z();
  const float cone = this->cone();
  // For one tap (float) or eight (Float8), with the same operations.
  auto can_hide = [&](auto z, auto d, float margin) {
    return (d - margin) * z * z_r <= cone * (z_r - z);
  };
  // Eight taps at once: z below the receiver's plane and, for an area light, inside the cone.
  // (A point light's cone is a line: its taps only smooth a hard edge.)
  const bool area_light = soft();
  auto blocks8 = [&](const Float8& z, const TapGroup& taps, float radius, int level) {
    const Int8 below = z < receiver_at(taps, radius, level);
    if (!area_light) return below;
    return below & can_hide(z, taps.distance * radius, kSmallestFilter * (1 << level));
  };
  if (area_light) {
    // Percentage-closer soft shadows: the penumbra grows with the receiver-blocker distance.
    // The search covers where a blocker could hide part of the light; it starts in the map's
    // own texels, within kReach of the point, and goes on at the level where the rest fits.
    const int most_coarse = static_cast<int>(coarse.size());
    const float widest = kReach * static_cast<float>(1 << most_coarse);
    // No farther than the map's nearest caster could hide any of the light from (can_hide
    // solved for d): on the object itself that is a few centimetres, on the backdrop behind it
    // tens.
    const float cone_of_nearest =
        nearest_depth < z_r ? cone * (z_r - nearest_depth) / (nearest_depth * z_r) : 0.0f;
    const float full_search =
        std::clamp(std::min(light_size_m / std::max(local.z(), 0.05f) * focal * 0.5f,
                            cone_of_nearest + kSmallestFilter),
                   2.0f, widest);
    const float search = std::min(full_search, kReach);
    // The level at which `radius` (texels of level 0) spans kReach texels or less.
    auto level_for = [&](float radius) {
      int level = 0;
      while (level < most_coarse && radius > kReach * static_cast<float>(1 << level)) ++level;
      return level;
    };
    // The filter over a disc of `radius`, once the search has found blockers.
    auto filter = [&](float radius) {
      const int level = level_for(radius);
      if (level == 0) {
        int lit = 0;
        for (const TapGroup& taps : filter_taps) {
          lit += 8 - simd::count(blocks8(disc8(taps, radius, 0), taps, radius, 0));
        }
        return static_cast<float>(lit) / 64;
      }
      Float8 hidden = {};
      for (const TapGroup& taps : filter_taps) {
        Float8 held;
        const Float8 z = disc8(taps, radius, level, &held);
        hidden += blocks8(z, taps, radius, level) ? held : Float8{};
      }
      return 1 - simd::sum(hidden) / 64;
    };
    // Blockers among `taps` over `radius` at `level`: their count and mean depth.
    auto search_blockers = [&](std::span<const TapGroup> tap_groups, float radius, int level,
                               float& mean_depth) {
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
    };
    // The filter's radius: the light seen from the receiver through the blockers' depth, as a
    // disc of the light's area (a square of side L: radius L / √π), so that a blocker wholly
    // inside hides the fraction of the light that it hides from the receiver.
    auto penumbra_texels = [&](float blocker) {
      constexpr float kDiscOfSquare = 0.56418958f;  // 1 / √π
      const float penumbra_m =
          kDiscOfSquare * light_size_m * (receiver - blocker) / std::max(blocker, 0.01f);
      return std::clamp(penumbra_m / texel, kSmallestFilter, widest);
    };
    // Whether nothing a reach map holds can hide the light from `distance` texels away, or
    // more: `nearest` is beyond the depth that can_hide allows there (solved for z; a margin
    // for rounding).
    auto clear_from = [&](float nearest, float distance) {
      return nearest * (cone + (distance - kSmallestFilter) * z_r) > z_r * cone * (1 + 1e-5f);
    };
    // Most points are plainly lit, and one test settles the map's own texels: the centre tap
    // is lit, and nothing within the taps' reach (the 5 x 5 blocks around the point's) is near
    // enough the light to hide any of it from the search radius's distance. Only blockers lower
    // still, inside the radius and missed by the centre tap, are left lit. (Four far taps at the
    // search area's corners used to settle many more, but they missed blockers between them and
    // the centre: near a box's foot the penumbra's outer edge came out as a step.) A point
    // outside the map is judged at the nearest texel inside: nothing in the map is nearer the
    // point than that texel is (a square is convex), and all of it is `outside_by` away or more.
    const float outside_by = std::max(
        {-u, -v, u - static_cast<float>(size - 1), v - static_cast<float>(size - 1), 0.0f});
    if (outside_by > full_search) return 1;
    const int inside_u = std::clamp(static_cast<int>(u), 0, size - 1);
    const int inside_v = std::clamp(static_cast<int>(v), 0, size - 1);
    const int reach_block = (inside_v / kBlock) * blocks_per_row + inside_u / kBlock;
    const bool near_clear = lookup(u, v) >= receiver &&
                            clear_from(reach_nearest[reach_block], std::max(search, outside_by));
    if (!near_clear) {
      follow_plane();
      float blocker = 0;
      const int blockers = search_blockers(kSearchTaps, search, 0, blocker);
      if (blockers > 0) {
        const float radius = penumbra_texels(blocker);
        // The whole search area blocks, and the penumbra is no wider: umbra.
        if (blockers == 16 && radius <= kReach) return 0;
        return filter(radius);
      }
    }
    // Farther out: level k's reach map covers the 5 x 5 of its blocks (16 texels of level k)
    // around the point's, and anything outside level k - 1's lies 2 of its blocks away or more.
    const int search_level = level_for(full_search);
    // Inside the map, the per-block bound holds these tests already made.
    bool far_clear = outside ? true : z_r < clear_below[reach_block * kLevelSlots + search_level];
    for (int level = 1; outside && level <= search_level && far_clear; ++level) {
      const Level& coarser = coarse[level - 1];
      const int block =
          (inside_v >> (4 + level)) * coarser.blocks_per_row + (inside_u >> (4 + level));
      far_clear = clear_from(coarser.reach_nearest[block],
                             std::max(static_cast<float>(16 << level), outside_by));
    }
    static_assert(kBlock == 16);
    if (far_clear) return 1;
    follow_plane();
    float blocker = 0;
    if (search_blockers(wide_search_taps, full_search, search_level, blocker) == 0) return 1;
    return filter(penumbra_texels(blocker));
  }
  // Other lights: a hard edge, smoothed over the smallest filter.
  follow_plane();
  int lit = 0;
  for (const TapGroup& taps : kSearchTaps) {
    lit += 8 - simd::count(blocks8(disc8(taps, kSmallestFilter, 0), taps, kSmallestFilter, 0));
  }
  return static_cast<float>(lit) / 16;
}

using Float8 = simd::F32x8;
using Int8 = simd::I32x8;
constexpr Float8 kTexelCentres = {0.5f, 1.5f, 2.5f, 3.5f, 4.5f, 5.5f, 6.5f, 7.5f};

// Shadow casters for one frame: world positions and the triangles over them.
struct CasterMesh {
  std::vector<Vector3f> positions;
  const std::vector<std::array<std::uint32_t, 3>>* triangles = nullptr;
  std::size_t first_closed = 0;  // triangles from here on bound solids: back faces skipped
};

// One row of a coarser shadow-map level from two rows of the finer one, `finer_size` texels (an
// odd last column alone): per texel, the nearest depth of its 2 x 2 and the fraction of them
// that hold a caster. At level 0 (`top_held` and `bottom_held` null) a caster is a finite depth.
void halve_rows(const float* top, const float* bottom, const float* top_held,
                const float* bottom_held, int finer_size, float* nearest, float* held) {
  const float inf = std::numeric_limits<float>::infinity();
  const Float8 one = Float8{} + 1.0f, none = {};
  constexpr Int8 kEven = {0, 2, 4, 6, 8, 10, 12, 14}, kOdd = {1, 3, 5, 7, 9, 11, 13, 15};
  auto held8 = [&](int x) {  // how many of the two rows' eight columns from x hold a caster
    if (top_held) return simd::load8(top_held + x) + simd::load8(bottom_held + x);
    return (simd::load8(top + x) < inf ? one : none) + (simd::load8(bottom + x) < inf ? one : none);
  };
  int x = 0;
  for (; x + 16 <= finer_size; x += 16) {  // eight texels from sixteen
    const Float8 top0 = simd::load8(top + x), top1 = simd::load8(top + x + 8);
    const Float8 bottom0 = simd::load8(bottom + x), bottom1 = simd::load8(bottom + x + 8);
    const Float8 near0 = top0 < bottom0 ? top0 : bottom0;
    const Float8 near1 = top1 < bottom1 ? top1 : bottom1;
    const Float8 even = __builtin_shuffle(near0, near1, kEven);
    const Float8 odd = __builtin_shuffle(near0, near1, kOdd);
    const Float8 out = even < odd ? even : odd;
    const Float8 held0 = held8(x), held1 = held8(x + 8);
    const Float8 fraction =
        (__builtin_shuffle(held0, held1, kEven) + __builtin_shuffle(held0, held1, kOdd)) * 0.25f;
    std::memcpy(nearest + x / 2, &out, sizeof(out));
    std::memcpy(held + x / 2, &fraction, sizeof(fraction));
  }
  auto held1 = [&](int x) {
    if (top_held) return top_held[x] + bottom_held[x];
    return static_cast<float>(std::isfinite(top[x])) + static_cast<float>(std::isfinite(bottom[x]));
  };
  for (; x < finer_size; x += 2) {
    const int next = std::min(x + 1, finer_size - 1);
    nearest[x / 2] = std::min({top[x], top[next], bottom[x], bottom[next]});
    held[x / 2] = 0.25f * (held1(x) + held1(next));
  }
}

void rasterize_depth(ShadowMap& map, const CasterMesh& casters) {
  const int size = map.size;
  const auto& tris = *casters.triangles;
  // Every vertex into light space once (vertices are shared by about six triangles).
  struct LightVertex {
    Vector2f s;
    float key;
    bool behind;
  };
  std::vector<LightVertex> light_vertices(casters.positions.size());
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, casters.positions.size(), 8192),
      [&](const tbb::blocked_range<size_t>& range) {
        for (size_t v = range.begin(); v != range.end(); ++v) {
          const Vector3f l = map.light_from_world * (casters.positions[v] - map.origin);
          LightVertex& out = light_vertices[v];
          if (map.orthographic) {
            out = {
                {l.x() * map.focal + size / 2.0f, l.y() * map.focal + size / 2.0f}, -l.z(), false};
          } else {
            out = {
                {l.x() / l.z() * map.focal + size / 2.0f, l.y() / l.z() * map.focal + size / 2.0f},
                1 / l.z(),
                l.z() <= kNear};
          }
        }
      });
  // Rasterized as a key that grows towards the light, one plane per triangle: -z for orthographic
  // maps (z is affine in screen space) and 1/z for perspective ones. Converted to z at the end.
  struct Projected {
    std::array<float, 3> w0_plane, w1_plane, key_plane;
    std::uint16_t x0, y0, x1, y1;
  };
  std::vector<Projected> projected(tris.size());
  std::vector<char> keep(tris.size(), 0);
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, tris.size(), 4096),
      [&](const tbb::blocked_range<size_t>& range) {
        for (size_t t = range.begin(); t != range.end(); ++t) {
          std::array<Vector2f, 3> s;
          std::array<float, 3> key;
          bool behind = false;
          for (int i = 0; i < 3; ++i) {
            const LightVertex& v = light_vertices[tris[t][i]];
            s[i] = v.s;
            key[i] = v.key;
            behind = behind || v.behind;
          }
          const float area = edge(s[0], s[1], s[2].x(), s[2].y());
          if (behind || std::abs(area) < 1e-12f) continue;
          if (t >= casters.first_closed) {
            // A solid's faces turned away from the light are behind its lit faces.
            const Vector3f& a = casters.positions[tris[t][0]];
            const Vector3f normal =
                (casters.positions[tris[t][1]] - a).cross(casters.positions[tris[t][2]] - a);
            const Vector3f towards =
                map.orthographic ? Vector3f(map.light_from_world.row(2)) : Vector3f(a - map.origin);
            if (normal.dot(towards) >= 0) continue;
          }
          const float min_x = std::min({s[0].x(), s[1].x(), s[2].x()});
          const float max_x = std::max({s[0].x(), s[1].x(), s[2].x()});
          const float min_y = std::min({s[0].y(), s[1].y(), s[2].y()});
          const float max_y = std::max({s[0].y(), s[1].y(), s[2].y()});
          if (max_x < 0 || max_y < 0 || min_x >= size || min_y >= size) continue;
          Projected& p = projected[t];
          // Texel centres at +0.5: texels whose centre can fall inside.
          p.x0 = static_cast<std::uint16_t>(std::max(0.0f, std::floor(min_x - 0.5f)));
          p.y0 = static_cast<std::uint16_t>(std::max(0.0f, std::floor(min_y - 0.5f)));
          p.x1 = static_cast<std::uint16_t>(std::min<float>(size - 1, std::ceil(max_x)));
          p.y1 = static_cast<std::uint16_t>(std::min<float>(size - 1, std::ceil(max_y)));
          ScreenTriangle planes;
          planes.inv_z = key;
          compute_planes(planes, s, 1 / area);
          p.w0_plane = planes.w0_plane;
          p.w1_plane = planes.w1_plane;
          p.key_plane = planes.inv_z_plane;
          keep[t] = 1;
        }
      });
  constexpr int kBandRows = 32;
  const int bands = (size + kBandRows - 1) / kBandRows;
  const CellBins bins = bin_items(static_cast<int>(tris.size()), bands, [&](int t, auto&& fn) {
    if (!keep[t]) return;
    for (int b = projected[t].y0 / kBandRows; b <= projected[t].y1 / kBandRows; ++b) fn(b);
  });
  const float empty = -std::numeric_limits<float>::infinity();
  map.depth = dslr::take_floats(static_cast<size_t>(size) * size);  // every band fills its rows
  // The reach map serves the soft shadows' lit test only (see ShadowMap::visibility); it is made
  // from each block's own nearest depth.
  const bool soft = map.soft();
  std::vector<float> block_nearest;
  if (soft) {
    map.blocks_per_row = (size + ShadowMap::kBlock - 1) / ShadowMap::kBlock;
    block_nearest.assign(static_cast<size_t>(map.blocks_per_row) * map.blocks_per_row, 0.0f);
  }
  // The first coarser level (see below) is made in the bands, while their rows are in cache.
  constexpr int kMostCoarseLevels = 6;
  auto wants_level = [&](int finer_size) {
    return static_cast<int>(map.coarse.size()) < kMostCoarseLevels && finer_size / 2 >= 16;
  };
  map.coarse.reserve(kMostCoarseLevels);
  if (soft && wants_level(size)) {
    ShadowMap::Level& first = map.coarse.emplace_back();
    first.size = size / 2;  // a whole number of groups of eight texels
    first.depth = dslr::take_floats(static_cast<size_t>(first.size) * first.size);
    first.coverage = dslr::take_floats(static_cast<size_t>(first.size) * first.size);
  }
  tbb::parallel_for(0, bands, [&](int band) {
    const int row0 = band * kBandRows, row1 = std::min(size, row0 + kBandRows);
    float* key_rows = map.depth.data() + static_cast<size_t>(row0) * size;
    std::fill(key_rows, key_rows + static_cast<size_t>(row1 - row0) * size, empty);
    for (std::int32_t i = bins.start[band]; i < bins.start[band + 1]; ++i) {
      const Projected& p = projected[bins.items[i]];
      const int y0 = std::max<int>(row0, p.y0), y1 = std::min<int>(row1 - 1, p.y1);
      // Eight texels at once from a multiple of eight (the map's size is one): lanes outside
      // the triangle fail its edge tests. No branch on "any inside": most triangles span one
      // or two groups, so it would mispredict about as often as it skipped a store.
      for (int y = y0; y <= y1; ++y) {
        const float py = y + 0.5f;
        float* row = map.depth.data() + static_cast<size_t>(y) * size;
        const float w0_y = p.w0_plane[1] * py, w1_y = p.w1_plane[1] * py;
        const float key_y = p.key_plane[1] * py;
        for (int x = p.x0 & ~7; x <= p.x1; x += 8) {
          const Float8 px = static_cast<float>(x) + kTexelCentres;
          const Float8 w0 = p.w0_plane[0] * px + w0_y + p.w0_plane[2];
          const Float8 w1 = p.w1_plane[0] * px + w1_y + p.w1_plane[2];
          const Int8 inside = (w0 >= 0) & (w1 >= 0) & (w0 + w1 <= 1);
          const Float8 key = p.key_plane[0] * px + key_y + p.key_plane[2];
          Float8 current;
          std::memcpy(&current, row + x, sizeof(current));
          const Float8 merged = inside & (key > current) ? key : current;
          std::memcpy(row + x, &merged, sizeof(merged));
        }
      }
    }
    const float inf = std::numeric_limits<float>::infinity();
    // The flag read once: the stores below might alias it, which kept the loop scalar.
    const bool orthographic = map.orthographic;
    float* const keys_end = map.depth.data() + static_cast<size_t>(row1) * size;
    if (orthographic) {
      for (float* key = key_rows; key != keys_end; ++key) *key = -*key;
    } else {
      for (float* key = key_rows; key != keys_end; ++key) *key = *key > 0 ? 1 / *key : inf;
    }
    // The band's blocks' nearest depths, while its rows are in cache (a band is whole blocks
    // high; the map is whole groups of eight texels wide).
    static_assert(kBandRows % ShadowMap::kBlock == 0 && ShadowMap::kBlock % 8 == 0);
    if (!soft) return;
    const float* depth = map.depth.data();
    if (!map.coarse.empty()) {
      // Level 1 for the band's row pairs.
      ShadowMap::Level& first = map.coarse.front();
      for (int y = row0; y < row1; y += 2) {
        const float* top = depth + static_cast<size_t>(y) * size;
        halve_rows(top, top + size, nullptr, nullptr, size,
                   first.depth.data() + static_cast<size_t>(y / 2) * first.size,
                   first.coverage.data() + static_cast<size_t>(y / 2) * first.size);
      }
    }
    for (int block_row0 = row0; block_row0 < row1; block_row0 += ShadowMap::kBlock) {
      const int block_row1 = std::min(row1, block_row0 + ShadowMap::kBlock);
      float* nearest =
          &block_nearest[static_cast<size_t>(block_row0 / ShadowMap::kBlock) * map.blocks_per_row];
      for (int block = 0; block < map.blocks_per_row; ++block) {
        const int x0 = block * ShadowMap::kBlock, x1 = std::min(size, x0 + ShadowMap::kBlock);
        Float8 least = Float8{} + inf;
        for (int y = block_row0; y < block_row1; ++y) {
          for (int x = x0; x < x1; x += 8) {
            Float8 z;
            std::memcpy(&z, depth + static_cast<size_t>(y) * size + x, sizeof(z));
            least = z < least ? z : least;
          }
        }
        float m = least[0];
        for (int k = 1; k < 8; ++k) m = std::min(m, least[k]);
        nearest[block] = m;
      }
    }
  });
  if (!soft) return;
  // Two passes of 5 (along rows, then along columns), clamped at the map's edges.
  auto nearest_of_five = [](const std::vector<float>& from, int blocks, bool along_rows) {
    std::vector<float> to(from.size());
    for (int by = 0; by < blocks; ++by) {
      for (int bx = 0; bx < blocks; ++bx) {
        const int at = along_rows ? bx : by;
        float m = std::numeric_limits<float>::infinity();
        for (int k = std::max(0, at - 2); k <= std::min(blocks - 1, at + 2); ++k) {
          m = std::min(
              m, from[static_cast<size_t>(along_rows ? by : k) * blocks + (along_rows ? k : bx)]);
        }
        to[static_cast<size_t>(by) * blocks + bx] = m;
      }
    }
    return to;
  };
  auto reach_of = [&](const std::vector<float>& nearest, int blocks) {
    return nearest_of_five(nearest_of_five(nearest, blocks, true), blocks, false);
  };
  map.reach_nearest = reach_of(block_nearest, map.blocks_per_row);
  for (const float nearest : block_nearest)
    map.nearest_depth = std::min(map.nearest_depth, nearest);

  // The coarser levels, down to 16 texels a side or 2^6 texels of `depth` a texel (taps reaching
  // 24 x 64 = 1536 texels, as far as the map is wide). Each texel and block is the nearest of
  // the 2 x 2 under it (an odd last row or column alone).
  const float* finer = map.depth.data();
  int finer_size = size;
  int finer_blocks = map.blocks_per_row;
  for (std::size_t k = 0; k < map.coarse.size() || wants_level(finer_size); ++k) {
    const bool made = k < map.coarse.size();  // level 1, in the bands
    ShadowMap::Level& level = made ? map.coarse[k] : map.coarse.emplace_back();
    const int n = made ? level.size : (finer_size + 1) / 2;
    const float* finer_coverage = k > 0 ? map.coarse[k - 1].coverage.data() : nullptr;
    if (!made) {
      level.size = n;
      level.depth = dslr::take_floats(static_cast<size_t>(n) * n);
      level.coverage = dslr::take_floats(static_cast<size_t>(n) * n);
      tbb::parallel_for(0, n, [&](int y) {
        const size_t top = static_cast<size_t>(2 * y) * finer_size;
        const size_t bottom = static_cast<size_t>(std::min(2 * y + 1, finer_size - 1)) * finer_size;
        halve_rows(finer + top, finer + bottom, finer_coverage ? finer_coverage + top : nullptr,
                   finer_coverage ? finer_coverage + bottom : nullptr, finer_size,
                   level.depth.data() + static_cast<size_t>(y) * n,
                   level.coverage.data() + static_cast<size_t>(y) * n);
      });
    }
    level.blocks_per_row = (n + ShadowMap::kBlock - 1) / ShadowMap::kBlock;
    std::vector<float> nearest(static_cast<size_t>(level.blocks_per_row) * level.blocks_per_row);
    for (int by = 0; by < level.blocks_per_row; ++by) {
      for (int bx = 0; bx < level.blocks_per_row; ++bx) {
        float m = std::numeric_limits<float>::infinity();
        for (int fy = 2 * by; fy <= std::min(2 * by + 1, finer_blocks - 1); ++fy) {
          for (int fx = 2 * bx; fx <= std::min(2 * bx + 1, finer_blocks - 1); ++fx) {
            m = std::min(m, block_nearest[static_cast<size_t>(fy) * finer_blocks + fx]);
          }
        }
        nearest[static_cast<size_t>(by) * level.blocks_per_row + bx] = m;
      }
    }
    level.reach_nearest = reach_of(nearest, level.blocks_per_row);
    block_nearest = std::move(nearest);
    finer = level.depth.data();
    finer_size = n;
    finer_blocks = level.blocks_per_row;
  }
  // The far lit test's bounds: ShadowMap::visibility's clear_from at each level (distance 16
  // texels of level 1 at level 1, and so on) solved for the receiver's depth, the least so far.
  static_assert(kMostCoarseLevels < ShadowMap::kLevelSlots);
  const int blocks = map.blocks_per_row;
  const float cone = map.cone(), widened = cone * (1 + 1e-5f);
  map.clear_below.assign(static_cast<size_t>(blocks) * blocks * ShadowMap::kLevelSlots,
                         std::numeric_limits<float>::infinity());
  tbb::parallel_for(0, blocks, [&](int by) {
    for (int bx = 0; bx < blocks; ++bx) {
      float* bounds =
          &map.clear_below[(static_cast<size_t>(by) * blocks + bx) * ShadowMap::kLevelSlots];
      for (int k = 1; k <= static_cast<int>(map.coarse.size()); ++k) {
        const ShadowMap::Level& level = map.coarse[k - 1];
        const float nearest =
            level.reach_nearest[static_cast<size_t>(by >> k) * level.blocks_per_row + (bx >> k)];
        const float distance = static_cast<float>(16 << k);
        const float excess = widened - nearest * (distance - ShadowMap::kSmallestFilter);
        const float bound =
            excess > 0 ? nearest * cone / excess : std::numeric_limits<float>::infinity();
        bounds[k] = std::min(bounds[k - 1], bound);
      }
    }
  });
}

ShadowMap build_shadow_map(const ir::Light& light, const Vector3f& center, float radius,
                           const CasterMesh& casters, int size) {
  ShadowMap map;
  map.size = (size + 7) / 8 * 8;  // whole groups of eight texels per row
  size = map.size;
  if (light.type == ir::LightType::kDirectional) {
    map.orthographic = true;
    map.light_from_world = light_frame(light.direction.cast<float>());
    map.origin = center - light.direction.cast<float>().normalized() * (radius * 4);
    map.focal = size / (2.2f * radius);
    map.texel_m = 1 / map.focal;
  } else {
    const Vector3f position = light.position.cast<float>();
    const float distance = (center - position).norm();
    if (distance <= radius * 1.05f) return map;  // light among the casters: no map, all lit
    map.light_from_world = light_frame(center - position);
    map.origin = position;
    const float half_angle = std::asin(std::min(0.999f, radius * 1.1f / distance));
    map.focal = size / (2 * std::tan(half_angle));
    map.texel_m_per_z = 1 / map.focal;
    if (light.type == ir::LightType::kArea) {
      map.light_size_m = static_cast<float>(std::max(light.size_m.x(), light.size_m.y()));
    }
  }
  rasterize_depth(map, casters);
  return map;
}

// A light with its constants in float, worked out once per frame rather than per pixel.
struct FrameLight {
  ir::LightType type = ir::LightType::kPoint;
  Vector3f position = Vector3f::Zero();
  Vector3f direction = Vector3f::UnitZ();  // unit
  // Directional: colour x illuminance (lux). Area: colour x on-axis intensity (cd). Point and
  // spot: colour x intensity (cd).
  Vector3f scaled_color = Vector3f::Zero();
  float spot_outer_cos = -1, spot_inner_cos = -1;

  explicit FrameLight(const ir::Light& light, const Vector3f& color)
      : type(light.type),
        position(light.position.cast<float>()),
        direction(light.direction.cast<float>().normalized()) {
    const float watts = static_cast<float>(light.power_w);
    switch (type) {
      case ir::LightType::kDirectional:
        scaled_color = color * static_cast<float>(light.illuminance_lx);
        break;
      case ir::LightType::kArea:
        // A one-sided Lambertian emitter of power P has intensity P/π along its normal.
        scaled_color = color * (kLumensPerWatt * watts / kPi);
        break;
      case ir::LightType::kPoint:
      case ir::LightType::kSpot: {
        scaled_color = color * (kLumensPerWatt * watts / (4 * kPi));
        const float half = static_cast<float>(light.spot_angle_rad / 2);
        spot_outer_cos = std::cos(half);
        spot_inner_cos = std::cos(half * (1 - static_cast<float>(light.spot_blend)));
        break;
      }
    }
  }
};

// Radiometry of one light at a point: the colour-weighted illuminance (lux) arriving along
// `to_light`.
struct LightSample {
  Vector3f to_light;
  Vector3f illuminance;  // per channel, lux
};

// Always inlined: GCC kept it a call from the lighting loop, which runs about a million times a
// frame (RenderFrame 2 % faster inlined, the same pixels).
__attribute__((always_inline)) inline bool sample_light(const FrameLight& light, const Vector3f& p,
                                                        LightSample* out) {
  if (light.type == ir::LightType::kDirectional) {
    out->to_light = -light.direction;
    out->illuminance = light.scaled_color;
    return true;
  }
  const Vector3f d = light.position - p;
  const float dist2 = std::max(d.squaredNorm(), 1e-6f);
  out->to_light = d / std::sqrt(dist2);
  float falloff = 1 / dist2;
  if (light.type == ir::LightType::kArea) {
    falloff *= std::max(0.0f, -light.direction.dot(out->to_light));
  } else if (light.type == ir::LightType::kSpot) {
    const float cos_axis = light.direction.dot(-out->to_light);
    const float t = std::clamp((cos_axis - light.spot_outer_cos) /
                                   std::max(light.spot_inner_cos - light.spot_outer_cos, 1e-4f),
                               0.0f, 1.0f);
    falloff *= t * t * (3 - 2 * t);
  }
  out->illuminance = light.scaled_color * falloff;
  return falloff > 0;
}

// GGX microfacet specular (Smith-Schlick visibility), times π so that it sits beside albedo/π·π.
float ggx_specular(float n_dot_l, float n_dot_v, float n_dot_h, float v_dot_h, float roughness,
                   float f0, float* fresnel_out) {
  const float alpha = std::max(roughness * roughness, 0.002f);
  const float a2 = alpha * alpha;
  const float denom = n_dot_h * n_dot_h * (a2 - 1) + 1;
  const float d = a2 / (kPi * denom * denom);
  const float k = alpha / 2;
  const float vis = 1 / ((n_dot_l * (1 - k) + k) * (n_dot_v * (1 - k) + k));
  const float fresnel =
      f0 + (1 - f0) * (1 - v_dot_h) * (1 - v_dot_h) * (1 - v_dot_h) * (1 - v_dot_h) * (1 - v_dot_h);
  *fresnel_out = fresnel;
  return d * vis * fresnel / 4;
}

struct ScreenSetup {
  std::vector<ScreenTriangle> tris;
  std::vector<std::array<Vector3f, 3>> clipped_bary;  // per clipped triangle, its corners'
  // Triangles per tile: tile_tris[tile_start[tile] .. tile_start[tile + 1]), in triangle order.
  std::vector<std::int32_t> tile_start;
  std::vector<std::int32_t> tile_tris;
  int tiles_x = 0;
  int tiles_y = 0;

  // Barycentrics in the source triangle of a point with barycentrics b in screen triangle t.
  Vector3f source_bary(const ScreenTriangle& t, const Vector3f& b) const {
    if (t.clipped < 0) return b;
    const auto& corner = clipped_bary[t.clipped];
    return b.x() * corner[0] + b.y() * corner[1] + b.z() * corner[2];
  }
};

// Transforms (camera_vertex(t, corner) -> camera space), clips, projects and bins every triangle.
// Chunks run in parallel and are joined in order, so the result (and any depth tie) matches a
// serial pass.
template <typename CameraVertex, typename Cullable>
ScreenSetup setup_screen(int total_tris, const CameraVertex& camera_vertex,
                         const Cullable& cullable, const dslr::Intrinsics& canvas) {
  ScreenSetup setup;
  const float fx = static_cast<float>(canvas.fx), fy = static_cast<float>(canvas.fy);
  const float cx = static_cast<float>(canvas.cx), cy = static_cast<float>(canvas.cy);
  const int width = canvas.width, height = canvas.height;
  struct Part {
    std::vector<ScreenTriangle> tris;
    std::vector<std::array<Vector3f, 3>> clipped_bary;
  };
  constexpr int kChunk = 16384;
  const int chunks = (total_tris + kChunk - 1) / kChunk;
  std::vector<Part> parts(chunks);
  tbb::parallel_for(0, chunks, [&](int chunk) {
    Part& part = parts[chunk];
    const int begin = chunk * kChunk, end = std::min(total_tris, begin + kChunk);
    part.tris.reserve(end - begin);
    // Projects a camera-space triangle; keeps it when it has area and touches the canvas.
    auto emit = [&](int source, const std::array<Vector3f, 3>& p, std::int32_t clipped) {
      ScreenTriangle s;
      std::array<Vector2f, 3> screen;
      for (int c = 0; c < 3; ++c) {
        s.inv_z[c] = 1 / p[c].z();
        // Pixel centres at +0.5: u = fx·x/z + cx puts the image centre at cx.
        screen[c] = {fx * p[c].x() * s.inv_z[c] + cx, fy * p[c].y() * s.inv_z[c] + cy};
      }
      const float area = edge(screen[0], screen[1], screen[2].x(), screen[2].y());
      if (std::abs(area) < 1e-10f) return false;
      const float min_x = std::min({screen[0].x(), screen[1].x(), screen[2].x()});
      const float max_x = std::max({screen[0].x(), screen[1].x(), screen[2].x()});
      const float min_y = std::min({screen[0].y(), screen[1].y(), screen[2].y()});
      const float max_y = std::max({screen[0].y(), screen[1].y(), screen[2].y()});
      if (max_x < 0 || max_y < 0 || min_x >= width || min_y >= height) return false;
      s.x0 = static_cast<std::uint16_t>(std::max(0.0f, std::floor(min_x)));
      s.y0 = static_cast<std::uint16_t>(std::max(0.0f, std::floor(min_y)));
      s.x1 = static_cast<std::uint16_t>(std::min<float>(width - 1, std::floor(max_x)));
      s.y1 = static_cast<std::uint16_t>(std::min<float>(height - 1, std::floor(max_y)));
      s.source = source;
      s.clipped = clipped;
      compute_planes(s, screen, 1 / area);
      part.tris.push_back(s);
      return true;
    };
    for (int t = begin; t < end; ++t) {
      std::array<Vector3f, 3> cam;
      for (int c = 0; c < 3; ++c) cam[c] = camera_vertex(t, c);
      // Back faces of closed solids: the camera (at the origin) is behind their plane.
      if (cullable(t) && (cam[1] - cam[0]).cross(cam[2] - cam[0]).dot(cam[0]) >= 0) continue;
      const int in_front = (cam[0].z() >= kNear) + (cam[1].z() >= kNear) + (cam[2].z() >= kNear);
      if (in_front == 0) continue;
      if (in_front == 3) {
        emit(t, cam, -1);
        continue;
      }
      clip_near(cam, [&](const std::array<Vector3f, 3>& p, const std::array<Vector3f, 3>& b) {
        if (emit(t, p, static_cast<std::int32_t>(part.clipped_bary.size()))) {
          part.clipped_bary.push_back(b);
        }
      });
    }
  });
  // Join the chunks in order.
  std::vector<size_t> tri_offset(chunks + 1, 0), clipped_offset(chunks + 1, 0);
  for (int c = 0; c < chunks; ++c) {
    tri_offset[c + 1] = tri_offset[c] + parts[c].tris.size();
    clipped_offset[c + 1] = clipped_offset[c] + parts[c].clipped_bary.size();
  }
  setup.tris.resize(tri_offset[chunks]);
  setup.clipped_bary.resize(clipped_offset[chunks]);
  tbb::parallel_for(0, chunks, [&](int c) {
    std::copy(parts[c].clipped_bary.begin(), parts[c].clipped_bary.end(),
              setup.clipped_bary.begin() + clipped_offset[c]);
    ScreenTriangle* out = setup.tris.data() + tri_offset[c];
    for (ScreenTriangle s : parts[c].tris) {
      if (s.clipped >= 0) s.clipped += static_cast<std::int32_t>(clipped_offset[c]);
      *out++ = s;
    }
    std::vector<ScreenTriangle>().swap(parts[c].tris);
  });

  // Bin into tiles.
  const int tiles_x = setup.tiles_x = (width + kTileSize - 1) / kTileSize;
  const int tiles_y = setup.tiles_y = (height + kTileSize - 1) / kTileSize;
  CellBins bins =
      bin_items(static_cast<int>(setup.tris.size()), tiles_x * tiles_y, [&](int i, auto&& fn) {
        const ScreenTriangle& t = setup.tris[i];
        for (int ty = t.y0 / kTileSize; ty <= t.y1 / kTileSize; ++ty) {
          for (int tx = t.x0 / kTileSize; tx <= t.x1 / kTileSize; ++tx) {
            fn(ty * tiles_x + tx);
          }
        }
      });
  setup.tile_start = std::move(bins.start);
  setup.tile_tris = std::move(bins.items);
  return setup;
}

// Four floats or four lane masks: one pixel's four samples, or four pixel centres in a row.
using Float4 = simd::F32x4;
using Int4 = simd::I32x4;

using simd::load4;
inline Int4 load4(const std::int32_t* p) {
  Int4 v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}
inline void store4(float* p, Float4 v) {
  std::memcpy(p, &v, sizeof(v));
}
inline void store4(std::int32_t* p, Int4 v) {
  std::memcpy(p, &v, sizeof(v));
}

// Visibility in tiles with `Samples` samples per pixel (1: the pixel centre; 4: a rotated grid),
// then resolve_tile(x0, y0, x1, y1, inv_z, tri) for every tile, with the samples of pixel
// (px, py) at ((py - y0)·kTileSize + px - x0)·Samples (tri -1: nothing there).
// Four samples are tested at once: a pixel's four, or four neighbouring pixel centres. Each lane
// evaluates the planes with the same expression as a scalar pass would, so coverage and depth
// ties come out the same.
// uniform_tile(x0, y0, x1, y1, id) is offered each tile where only the plane of screen triangle
// `id` shows (the studio's big planes; see below): returning true, it has written the tile itself
// and the samples are skipped. face_of(triangle) names the convex planar face a triangle belongs
// to (-1: none), so that the triangles of one face may cover a tile together; nullptr: no tile is
// offered (the callers that shade every pixel themselves).
template <int Samples, typename FaceOf, typename UniformTile, typename ResolveTile>
void rasterize_tiles(const ScreenSetup& setup, const dslr::Intrinsics& canvas,
                     const FaceOf& face_of, const UniformTile& uniform_tile,
                     const ResolveTile& resolve_tile) {
  static_assert(Samples == 1 || Samples == kSamples);
  static_assert(kTileSize % 4 == 0);
  // Lane offsets from the pixel (Samples 4) or from the first of four pixels (Samples 1).
  const Float4 lane_x = Samples == 1 ? Float4{0.5f, 1.5f, 2.5f, 3.5f}
                                     : Float4{kSampleX[0], kSampleX[1], kSampleX[2], kSampleX[3]};
  const Float4 lane_y = Samples == 1 ? Float4{0.5f, 0.5f, 0.5f, 0.5f}
                                     : Float4{kSampleY[0], kSampleY[1], kSampleY[2], kSampleY[3]};
  constexpr int kStepX = Samples == 1 ? 4 : 1;  // pixels per group of four lanes
  using Float8 = simd::F32x8;
  using Int8 = simd::I32x8;
  const Float8 lane_x8 = {kSampleX[0],     kSampleX[1],     kSampleX[2],     kSampleX[3],
                          1 + kSampleX[0], 1 + kSampleX[1], 1 + kSampleX[2], 1 + kSampleX[3]};
  const Float8 lane_y8 = {kSampleY[0], kSampleY[1], kSampleY[2], kSampleY[3],
                          kSampleY[0], kSampleY[1], kSampleY[2], kSampleY[3]};
  tbb::parallel_for(
      tbb::blocked_range<int>(0, setup.tiles_x * setup.tiles_y, 4),
      [&](const tbb::blocked_range<int>& range) {
        alignas(64) float sample_inv_z[kTileSize * kTileSize * Samples];
        alignas(64) std::int32_t sample_tri[kTileSize * kTileSize * Samples];
        for (int tile = range.begin(); tile != range.end(); ++tile) {
          const int tx = tile % setup.tiles_x, ty = tile / setup.tiles_x;
          const int x0 = tx * kTileSize, y0 = ty * kTileSize;
          const int x1 = std::min(x0 + kTileSize, canvas.width);
          const int y1 = std::min(y0 + kTileSize, canvas.height);
          // Without a face_of (nullptr), no tile is offered whole.
          if constexpr (!std::is_same_v<FaceOf, std::nullptr_t>) {
            // Each triangle against the box of the tile's samples: inside all three edges at
            // the four corners (covers), outside one edge at all four (misses), or neither.
            // The planes are affine, so the corners decide; a margin keeps rounding out.
            constexpr float kMargin = 1e-4f, kBehindMargin = 1e-3f;
            const float bx0 = x0 + (Samples == 1 ? 0.5f : 0.125f);
            const float bx1 = x1 - 1 + (Samples == 1 ? 0.5f : 0.875f);
            const float by0 = y0 + (Samples == 1 ? 0.5f : 0.125f);
            const float by1 = y1 - 1 + (Samples == 1 ? 0.5f : 0.875f);
            const Float4 cx = {bx0, bx1, bx0, bx1}, cy = {by0, by0, by1, by1};
            // One convex plane alone may show in the box: the nearest triangle with a corner of
            // the box inside it, together with the triangles of its convex face (the two of a
            // quad, the strips of a disc), when each corner lies inside one of them (a convex
            // polygon holding the four corners holds the box) and every other triangle's plane
            // lies behind it at all four corners (1/z is affine: then at every sample too). The
            // studio's planes overlap: the floor runs on behind the green screen, the
            // turntable's stand behind its disc.
            struct Seen {
              std::int32_t id, face;
              Float4 inv_z;
              Int4 in;
            };
            constexpr int kMaxSeen = 32;  // a busier bin is the object's, never one plane
            std::array<Seen, kMaxSeen> seen;
            int seen_count = 0, front = -1;
            float front_inv_z = 0;
            auto all = [](Int4 m) { return m[0] && m[1] && m[2] && m[3]; };
            for (std::int32_t i = setup.tile_start[tile]; i < setup.tile_start[tile + 1]; ++i) {
              const ScreenTriangle& s = setup.tris[setup.tile_tris[i]];
              const Float4 w0 = s.w0_plane[0] * cx + s.w0_plane[1] * cy + s.w0_plane[2];
              const Float4 w1 = s.w1_plane[0] * cx + s.w1_plane[1] * cy + s.w1_plane[2];
              const Float4 w2 = 1 - (w0 + w1);
              const Int4 out0 = w0 < -kMargin, out1 = w1 < -kMargin, out2 = w2 < -kMargin;
              if (all(out0) || all(out1) || all(out2)) continue;  // misses
              if (seen_count == kMaxSeen) {
                front = -1;
                break;
              }
              const Int4 in = (w0 >= kMargin) & (w1 >= kMargin) & (w2 >= kMargin);
              const Float4 inv_z = s.inv_z_plane[0] * cx + s.inv_z_plane[1] * cy + s.inv_z_plane[2];
              seen[seen_count] = {setup.tile_tris[i], face_of(s), inv_z, in};
              const float centre_inv_z = 0.5f * (inv_z[0] + inv_z[3]);
              if ((in[0] || in[1] || in[2] || in[3]) && (front < 0 || centre_inv_z > front_inv_z)) {
                front = seen_count;
                front_inv_z = centre_inv_z;
              }
              ++seen_count;
            }
            if (front >= 0) {
              const Seen& plane = seen[front];
              // Behind by more than float rounding can move a sample's 1/z.
              const Float4 behind = plane.inv_z - kBehindMargin * plane.inv_z;
              Int4 covered = plane.in;
              bool alone = plane.inv_z[0] > 0 && plane.inv_z[3] > 0;
              for (int k = 0; k < seen_count && alone; ++k) {
                if (k == front) continue;
                if (plane.face >= 0 && seen[k].face == plane.face) {
                  covered |= seen[k].in;
                } else {
                  alone = all(seen[k].inv_z < behind);
                }
              }
              if (alone && all(covered) && uniform_tile(x0, y0, x1, y1, plane.id)) continue;
            }
          }
          std::fill(std::begin(sample_inv_z), std::end(sample_inv_z), 0.0f);
          std::fill(std::begin(sample_tri), std::end(sample_tri), -1);
          const std::int32_t* bin = setup.tile_tris.data();
          for (std::int32_t i = setup.tile_start[tile]; i < setup.tile_start[tile + 1]; ++i) {
            const std::int32_t id = bin[i];
            const ScreenTriangle& s = setup.tris[id];
            // Groups of four pixel centres start at multiples of four inside the tile; lanes
            // outside the triangle's box fail its edge tests, lanes past the canvas are never
            // resolved.
            const int px0 =
                Samples == 1 ? x0 + ((std::max<int>(x0, s.x0) - x0) & ~3) : std::max<int>(x0, s.x0);
            const int px1 = std::min<int>(x1 - 1, s.x1);
            const int py0 = std::max<int>(y0, s.y0), py1 = std::min<int>(y1 - 1, s.y1);
            const Int4 id4 = Int4{} + id;
            const Int8 id8 = Int8{} + id;
            // A triangle that covers the whole box of samples (the studio's big ones) needs only
            // the depth test: the planes are affine, so the box's corners decide, with a margin
            // for rounding.
            bool covers_box = false;
            {
              constexpr float kMargin = 1e-4f;
              const float bx0 = px0 + (Samples == 1 ? 0.5f : 0.125f);
              const float bx1 = px1 + (Samples == 1 ? 0.5f + kStepX - 1 : 0.875f);
              const float by0 = py0 + (Samples == 1 ? 0.5f : 0.125f);
              const float by1 = py1 + (Samples == 1 ? 0.5f : 0.875f);
              const Float4 cx = {bx0, bx1, bx0, bx1}, cy = {by0, by0, by1, by1};
              const Float4 w0 = s.w0_plane[0] * cx + s.w0_plane[1] * cy + s.w0_plane[2];
              const Float4 w1 = s.w1_plane[0] * cx + s.w1_plane[1] * cy + s.w1_plane[2];
              const Int4 inside = (w0 >= kMargin) & (w1 >= kMargin) & (w0 + w1 <= 1 - kMargin);
              covers_box = inside[0] && inside[1] && inside[2] && inside[3];
            }
            if (covers_box) {
              for (int py = py0; py <= py1; ++py) {
                const Float4 sy = static_cast<float>(py) + lane_y;
                const Float4 iz_row = s.inv_z_plane[1] * sy;
                for (int px = px0; px <= px1; px += kStepX) {
                  const Float4 sx = static_cast<float>(px) + lane_x;
                  const Float4 inv_z = s.inv_z_plane[0] * sx + iz_row + s.inv_z_plane[2];
                  const int base = ((py - y0) * kTileSize + (px - x0)) * Samples;
                  const Float4 nearest = load4(sample_inv_z + base);
                  const Int4 hit = inv_z > nearest;
                  store4(sample_inv_z + base, hit ? inv_z : nearest);
                  store4(sample_tri + base, hit ? id4 : load4(sample_tri + base));
                }
              }
              continue;
            }
            // Four lanes at (px, py): edge and depth tests, nearest depth and triangle kept
            // (stored hit or not, as below).
            auto test4 = [&](int px, int py, Float4 w0_row, Float4 w1_row, Float4 iz_row) {
              const Float4 sx = static_cast<float>(px) + lane_x;
              const Float4 w0 = s.w0_plane[0] * sx + w0_row + s.w0_plane[2];
              const Float4 w1 = s.w1_plane[0] * sx + w1_row + s.w1_plane[2];
              const Float4 inv_z = s.inv_z_plane[0] * sx + iz_row + s.inv_z_plane[2];
              const int base = ((py - y0) * kTileSize + (px - x0)) * Samples;
              const Float4 nearest = load4(sample_inv_z + base);
              const Int4 hit = (w0 >= 0) & (w1 >= 0) & (w0 + w1 <= 1) & (inv_z > nearest);
              store4(sample_inv_z + base, hit ? inv_z : nearest);
              store4(sample_tri + base, hit ? id4 : load4(sample_tri + base));
            };
            if constexpr (Samples == kSamples) {
              // Two pixels' eight samples per step (one 8-lane register), the odd last one on
              // four lanes. The lanes of the second pixel compute px + (1 + offset), which is
              // exactly (px + 1) + offset in floats: the same coverage and depths. Every step
              // stores, hit or not: a branch on "any hit" mispredicts at each row's two edges
              // (the stores go to the tile's own buffers, in L1).
              for (int py = py0; py <= py1; ++py) {
                const Float8 sy = static_cast<float>(py) + lane_y8;
                const Float8 w0_row = s.w0_plane[1] * sy;
                const Float8 w1_row = s.w1_plane[1] * sy;
                const Float8 iz_row = s.inv_z_plane[1] * sy;
                int px = px0;
                for (; px + 1 <= px1; px += 2) {
                  const Float8 sx = static_cast<float>(px) + lane_x8;
                  const Float8 w0 = s.w0_plane[0] * sx + w0_row + s.w0_plane[2];
                  const Float8 w1 = s.w1_plane[0] * sx + w1_row + s.w1_plane[2];
                  const Float8 inv_z = s.inv_z_plane[0] * sx + iz_row + s.inv_z_plane[2];
                  const int base = ((py - y0) * kTileSize + (px - x0)) * Samples;
                  Float8 nearest;
                  std::memcpy(&nearest, sample_inv_z + base, sizeof(nearest));
                  const Int8 hit = (w0 >= 0) & (w1 >= 0) & (w0 + w1 <= 1) & (inv_z > nearest);
                  Int8 ids;
                  std::memcpy(&ids, sample_tri + base, sizeof(ids));
                  const Float8 new_z = hit ? inv_z : nearest;
                  const Int8 new_ids = hit ? id8 : ids;
                  std::memcpy(sample_inv_z + base, &new_z, sizeof(new_z));
                  std::memcpy(sample_tri + base, &new_ids, sizeof(new_ids));
                }
                if (px == px1) {
                  const Float4 sy4 = static_cast<float>(py) + lane_y;
                  test4(px, py, s.w0_plane[1] * sy4, s.w1_plane[1] * sy4, s.inv_z_plane[1] * sy4);
                }
              }
              continue;
            }
            for (int py = py0; py <= py1; ++py) {
              const Float4 sy = static_cast<float>(py) + lane_y;
              const Float4 w0_row = s.w0_plane[1] * sy;
              const Float4 w1_row = s.w1_plane[1] * sy;
              const Float4 iz_row = s.inv_z_plane[1] * sy;
              for (int px = px0; px <= px1; px += kStepX) test4(px, py, w0_row, w1_row, iz_row);
            }
          }
          resolve_tile(x0, y0, x1, y1, sample_inv_z, sample_tri);
        }
      });
}

// resolve(px, py, inv_z[Samples], tri[Samples]) for every pixel of every tile.
template <int Samples, typename Resolve>
void rasterize_pixels(const ScreenSetup& setup, const dslr::Intrinsics& canvas,
                      const Resolve& resolve) {
  rasterize_tiles<Samples>(
      setup, canvas, nullptr, [](int, int, int, int, std::int32_t) { return false; },
      [&](int x0, int y0, int x1, int y1, const float* inv_z, const std::int32_t* tri) {
        for (int py = y0; py < y1; ++py) {
          for (int px = x0; px < x1; ++px) {
            const int base = ((py - y0) * kTileSize + (px - x0)) * Samples;
            resolve(px, py, inv_z + base, tri + base);
          }
        }
      });
}

// The mesh triangle a screen triangle came from: object triangles first, then the studio's.
struct SourceTriangle {
  const scene::Geometry& g;
  int local;  // index in g
  bool is_object;
  const std::array<std::uint32_t, 3>& corners() const { return g.triangles[local]; }
  int material() const { return g.triangle_material[local]; }
  // A per-vertex attribute at barycentrics b.
  template <typename T>
  T at(const std::vector<T>& values, const Vector3f& b) const {
    const auto& c = corners();
    return b.x() * values[c[0]] + b.y() * values[c[1]] + b.z() * values[c[2]];
  }
};

// Where everything is for one frame: the object turned to its angle, the camera.
struct FrameContext {
  FrameContext(const ir::Scene& scene, const scene::StudioScene& studio,
               const FrameRequest& request)
      : object(studio.object),
        room(studio.studio),
        closed_studio_tris(studio.closed_studio_triangles),
        object_closed(studio.object_closed) {
    const ir::Mat4 world_from_object = ir::world_from_object(scene, request.turntable_angle_rad);
    object_rot = world_from_object.block<3, 3>(0, 0).cast<float>();
    object_t = world_from_object.block<3, 1>(0, 3).cast<float>();
    const ir::Mat4 camera_from_world = request.world_from_camera.inverse();
    cam_rot = camera_from_world.block<3, 3>(0, 0).cast<float>();
    cam_t = camera_from_world.block<3, 1>(0, 3).cast<float>();
    eye = request.world_from_camera.block<3, 1>(0, 3).cast<float>();
    object_tris = static_cast<int>(object.triangles.size());
    total_tris = object_tris + static_cast<int>(room.triangles.size());
  }
  // Object triangles come first, then the studio's.
  Vector3f world_vertex(int tri, int corner) const {
    if (tri < object_tris) {
      return object_rot * object.positions[object.triangles[tri][corner]] + object_t;
    }
    return room.positions[room.triangles[tri - object_tris][corner]];
  }
  ScreenSetup setup(const dslr::Intrinsics& canvas) const {
    // One affine map per mesh, written out: Eigen's generic product did not inline here.
    const Matrix3f object_to_cam = cam_rot * object_rot;
    const Vector3f object_to_cam_t = cam_rot * object_t + cam_t;
    auto apply = [](const Matrix3f& m, const Vector3f& t, const Vector3f& p) {
      return Vector3f(m(0, 0) * p.x() + m(0, 1) * p.y() + m(0, 2) * p.z() + t.x(),
                      m(1, 0) * p.x() + m(1, 1) * p.y() + m(1, 2) * p.z() + t.y(),
                      m(2, 0) * p.x() + m(2, 1) * p.y() + m(2, 2) * p.z() + t.z());
    };
    return setup_screen(
        total_tris,
        [&](int t, int c) {
          if (t < object_tris) {
            return apply(object_to_cam, object_to_cam_t, object.positions[object.triangles[t][c]]);
          }
          return apply(cam_rot, cam_t, room.positions[room.triangles[t - object_tris][c]]);
        },
        [&](int t) {
          return t < object_tris ? object_closed : t - object_tris < closed_studio_tris;
        },
        canvas);
  }

  const scene::Geometry& object;
  const scene::Geometry& room;
  Matrix3f object_rot, cam_rot;
  Vector3f object_t, cam_t, eye;
  int closed_studio_tris = 0;
  bool object_closed = false;
  int object_tris = 0, total_tris = 0;
};

}  // namespace

dslr::LinearFrame render_frame(const ir::Scene& scene, const scene::StudioScene& studio,
                               const FrameRequest& request, RasterTimings* timings) {
  const dslr::Intrinsics& canvas = request.canvas;
  // Tells this frame's per-thread caches from those any earlier frame left behind.
  static std::atomic<std::uint64_t> frames_started{0};
  const std::uint64_t frame_serial = ++frames_started;
  dslr::LinearFrame frame;
  frame.width = canvas.width;
  frame.height = canvas.height;
  frame.fx = canvas.fx;
  frame.fy = canvas.fy;
  frame.cx = canvas.cx;
  frame.cy = canvas.cy;
  const size_t pixel_count = static_cast<size_t>(canvas.width) * canvas.height;
  // Reused buffers: the resolve pass writes every pixel of all three.
  frame.rgb = dslr::take_floats(pixel_count * 3);
  frame.depth_m = dslr::take_floats(pixel_count);
  frame.mask = dslr::take_bytes(pixel_count);
  // Shading sums non-negative light with finite weights (GGX's roughness is floored).
  frame.rgb_clean = true;
  // Each finished tile's ranges for the depth of field, taken while its pixels are in cache.
  static_assert(kTileSize % dslr::TileRanges::kTile == 0);
  frame.tile_ranges.resize_for(canvas.width, canvas.height);
  auto record_ranges = [&frame](int x0, int y0, int x1, int y1) {
    dslr::record_tile_ranges(frame.rgb.data(), frame.depth_m.data(), frame.width, x0, y0, x1, y1,
                             frame.tile_ranges);
  };

  const FrameContext context(scene, studio, request);
  const Matrix3f& object_rot = context.object_rot;
  const Vector3f& object_t = context.object_t;
  const Matrix3f& cam_rot = context.cam_rot;
  const Vector3f& cam_t = context.cam_t;
  const Vector3f& eye = context.eye;
  const scene::Geometry& object = studio.object;
  const scene::Geometry& room = studio.studio;
  const int object_tris = context.object_tris;

  // Shadow maps: one per light, over the object (at this turntable angle) and the turntable.
  auto shadow_start = Clock::now();
  CasterMesh casters;
  casters.triangles = &studio.shadow_casters;
  casters.first_closed = studio.first_closed_caster;
  casters.positions.resize(object.positions.size() + room.positions.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, object.positions.size(), 8192),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t v = range.begin(); v != range.end(); ++v) {
                        casters.positions[v] = object_rot * object.positions[v] + object_t;
                      }
                    });
  std::copy(room.positions.begin(), room.positions.end(),
            casters.positions.begin() + object.positions.size());
  const Vector3f caster_center = object_rot * studio.object_center.cast<float>() + object_t;
  const float table_radius = static_cast<float>(scene.studio.turntable.diameter_m / 2);
  const float caster_radius =
      std::max(static_cast<float>(studio.object_radius),
               std::sqrt(table_radius * table_radius +
                         std::pow(caster_center.z() - object_t.z() +
                                      static_cast<float>(scene.studio.turntable.thickness_m),
                                  2.0f)));
  // The lights' maps together: each map's passes have serial joins that leave a core idle.
  std::vector<ShadowMap> shadow_maps(scene.studio.lights.size());
  // The maps' depth buffers (16 MB each at full resolution) go back to the pool for the next
  // frame's maps, whichever way this function returns.
  struct RecycleMaps {
    std::vector<ShadowMap>& maps;
    ~RecycleMaps() {
      for (ShadowMap& map : maps) {
        dslr::recycle(std::move(map.depth));
        for (ShadowMap::Level& level : map.coarse) {
          dslr::recycle(std::move(level.depth));
          dslr::recycle(std::move(level.coverage));
        }
      }
    }
  } recycle_maps{shadow_maps};
  tbb::parallel_for(std::size_t{0}, shadow_maps.size(), [&](std::size_t l) {
    shadow_maps[l] = build_shadow_map(scene.studio.lights[l], caster_center, caster_radius, casters,
                                      request.shadow_map_size);
  });
  if (timings) timings->shadow_ms += ms_since(shadow_start);

  // Transform, clip and project every triangle; bin into tiles.
  const auto setup_start = Clock::now();
  const ScreenSetup setup = context.setup(canvas);
  const auto& screen_tris = setup.tris;
  const float fx = static_cast<float>(canvas.fx);
  if (timings) timings->setup_ms += ms_since(setup_start);

  // Lights and the ambient term, once.
  std::vector<FrameLight> lights;
  for (const auto& light : scene.studio.lights)
    lights.emplace_back(light, light.color.cast<float>());
  const float ambient_lx = static_cast<float>(scene.studio.ambient_lx);

  // A point on one triangle as the camera sees it: everything shading needs besides the lights.
  struct SurfacePoint {
    Vector3f p;          // world
    Vector3f n;          // unit shading normal, turned towards the viewer
    Vector3f geometric;  // unit face normal, turned towards the viewer (shadow bias)
    Vector3f v;          // unit, towards the eye
    float footprint_m;   // surface size of a pixel, for texture and pattern filtering
    int material;
  };
  auto unit = [](const Vector3f& x) -> Vector3f { return x * (1 / std::sqrt(x.squaredNorm())); };
  auto source_of = [&](const ScreenTriangle& s) -> SourceTriangle {
    const bool is_object = s.source < object_tris;
    return {is_object ? object : room, is_object ? s.source : s.source - object_tris, is_object};
  };
  // Barycentrics in the source triangle at (px, py), clamped to it.
  auto source_bary_at = [&](const ScreenTriangle& s, float px, float py) -> Vector3f {
    const Vector3f b = setup.source_bary(s, screen_bary(s, px, py)).cwiseMax(0.0f);
    return b * (1 / b.sum());
  };
  // `on_plane`: barycentrics unclamped, so points past the triangle's edges stay on its plane.
  auto surface_at = [&](const ScreenTriangle& s, float px, float py,
                        bool on_plane = false) -> SurfacePoint {
    const SourceTriangle source = source_of(s);
    const bool is_object = source.is_object;
    const Vector3f b =
        on_plane ? setup.source_bary(s, screen_bary(s, px, py)) : source_bary_at(s, px, py);
    const Vector3f p_local = source.at(source.g.positions, b);
    const Vector3f n_local = source.at(source.g.normals, b);
    SurfacePoint sp;
    sp.p = is_object ? Vector3f(object_rot * p_local + object_t) : p_local;
    sp.n = unit(is_object ? Vector3f(object_rot * n_local) : n_local);
    sp.v = unit(eye - sp.p);
    // Geometric normal for shadow bias; shading normals are flipped towards the viewer, so
    // back faces of open meshes still shade.
    const Vector3f& face_normal = source.g.face_normals[source.local];
    sp.geometric = is_object ? Vector3f(object_rot * face_normal) : face_normal;
    if (sp.geometric.dot(sp.v) < 0) sp.geometric = -sp.geometric;
    if (sp.n.dot(sp.v) < 0) sp.n = -sp.n;
    sp.material = source.material();
    const float depth = (cam_rot * sp.p + cam_t).z();
    sp.footprint_m = depth / fx / std::max(std::abs(sp.n.dot(sp.v)), 0.2f);
    return sp;
  };
  // Whether the shading normal at (px, py), turned towards the viewer, lies within
  // kQuadNormalCos of the unit normal of `centre`, a point of the same surface under a pixel away.
  // The viewer's side is taken from the centre's view direction instead of the pixel's own (they
  // differ by a pixel's angle), which spares the pixel's surface point; and the cosine is compared
  // squared, which spares a square root and a division.
  auto normal_agrees = [&](const ScreenTriangle& s, float px, float py,
                           const SurfacePoint& centre) {
    const SourceTriangle source = source_of(s);
    const Vector3f n_local = source.at(source.g.normals, source_bary_at(s, px, py));
    const Vector3f n = source.is_object ? Vector3f(object_rot * n_local) : n_local;
    const float along = n.dot(centre.v) < 0 ? -n.dot(centre.n) : n.dot(centre.n);
    return along > 0 && along * along >= kQuadNormalCos * kQuadNormalCos * n.squaredNorm();
  };
  // Base colour x texture at (px, py) on the screen triangle, and where on the object (in its
  // own frame) the surface pattern is to be read, when it has one.
  struct AlbedoSample {
    Vector3f color;
    Vector3f pattern_at;
    bool patterned = false;
  };
  auto albedo_sample_at = [&](const ScreenTriangle& s, float px, float py) -> AlbedoSample {
    const SourceTriangle source = source_of(s);
    const bool is_object = source.is_object;
    const scene::ShadedMaterial& material = studio.materials[source.material()];
    const bool textured =
        material.texture >= 0 && material.texture < static_cast<int>(studio.textures.size());
    AlbedoSample out;
    out.color = material.base_color;
    out.patterned = is_object && scene::has_pattern(material.pattern);
    if (!textured && !out.patterned) return out;
    const Vector3f b = source_bary_at(s, px, py);
    if (textured) {
      const scene::MipTexture& texture = studio.textures[material.texture];
      auto uv_at = [&](float qx, float qy) {
        return source.at(source.g.uvs, setup.source_bary(s, screen_bary(s, qx, qy)));
      };
      const Vector2f uv = source.at(source.g.uvs, b);
      const Vector2f du = uv_at(px + 1, py) - uv_at(px, py);
      const Vector2f dv = uv_at(px, py + 1) - uv_at(px, py);
      const float texels =
          std::max(du.norm(), dv.norm()) *
          static_cast<float>(std::max(texture.levels[0].width, texture.levels[0].height));
      out.color = out.color.cwiseProduct(texture.sample(uv, texels));
    }
    if (out.patterned) out.pattern_at = source.at(source.g.positions, b);
    return out;
  };
  // Base colour x texture x surface pattern at (px, py) on the screen triangle.
  auto albedo_at = [&](const ScreenTriangle& s, float px, float py, float footprint_m) -> Vector3f {
    AlbedoSample sample = albedo_sample_at(s, px, py);
    if (sample.patterned) {
      const scene::ShadedMaterial& material = studio.materials[source_of(s).material()];
      sample.color *= scene::pattern_factor(material.pattern, sample.pattern_at, footprint_m);
    }
    return sample.color;
  };
  // albedo_at for up to 16 pixels of one material at once (the pattern is evaluated eight
  // pixels at a time): pixel i at (px[i], py[i]) on screen triangle tris[i], with the footprint
  // `footprint_m` (a float: all alike; a pointer: one per pixel).
  constexpr int kMaxBatch = 16;
  auto albedo_batch = [&](const int* tris, const int* px, const int* py, int count,
                          auto footprint_m, Vector3f* out) {
    std::array<float, kMaxBatch> x, y, z, factor;
    int patterned = 0;
    for (int i = 0; i < count; ++i) {
      const AlbedoSample sample =
          albedo_sample_at(screen_tris[tris[i]], px[i] + 0.5f, py[i] + 0.5f);
      out[i] = sample.color;
      patterned += sample.patterned;
      x[i] = sample.pattern_at.x();
      y[i] = sample.pattern_at.y();
      z[i] = sample.pattern_at.z();
    }
    if (patterned == 0) return;
    // One material: either every pixel has the pattern or none does.
    const scene::ShadedMaterial& material =
        studio.materials[source_of(screen_tris[tris[0]]).material()];
    scene::pattern_factors(material.pattern, x.data(), y.data(), z.data(), count, footprint_m,
                           factor.data());
    for (int i = 0; i < count; ++i) out[i] *= factor[i];
  };
  // The BRDF is linear in the albedo, so the light a surface point sends to the camera is
  // albedo ⊙ scale + offset: the lights are summed once and the albedo applied per pixel.
  struct Lighting {
    Vector3f scale, offset;
  };
  auto lighting_at = [&](const SurfacePoint& sp) -> Lighting {
    const scene::ShadedMaterial& material = studio.materials[sp.material];
    const float metallic = material.metallic;
    // Ambient: a uniform white room of the given illuminance.
    Vector3f diffuse = Vector3f::Constant(ambient_lx / kPi);
    Vector3f specular_sum = Vector3f::Zero();
    const float n_dot_v = std::max(sp.n.dot(sp.v), 1e-3f);
    const float f0 = 0.04f * (1 - metallic) + metallic;
    for (size_t l = 0; l < lights.size(); ++l) {
      LightSample sample;
      if (!sample_light(lights[l], sp.p, &sample)) continue;
      const float n_dot_l = sp.n.dot(sample.to_light);
      const float geo_dot_l = sp.geometric.dot(sample.to_light);
      if (n_dot_l <= 0 || geo_dot_l <= -0.05f) continue;
      const float visibility =
          shadow_maps[l].visibility(sp.p, sp.geometric, std::max(geo_dot_l, 0.0f));
      if (visibility <= 0) continue;
      const Vector3f h = unit(sample.to_light + sp.v);
      float fresnel = 0;
      const float specular =
          ggx_specular(n_dot_l, n_dot_v, std::max(sp.n.dot(h), 0.0f), std::max(sp.v.dot(h), 0.0f),
                       material.roughness, f0, &fresnel);
      const Vector3f arriving = sample.illuminance * (n_dot_l * visibility);
      diffuse += arriving * ((1 - fresnel) / kPi);
      specular_sum += arriving * specular;
    }
    // brdf = albedo·(1 - metallic)·(1 - F)/π + spec_colour·specular, where the specular colour
    // is white for dielectrics and blends towards the albedo with the metallic factor.
    return {diffuse * (1 - metallic) + specular_sum * metallic, specular_sum * (1 - metallic)};
  };
  // Four pixels of one surface and material, each shaded as shade() does (its own normal, light
  // and footprint), with their albedos batched: pixel i at (px[i], py[i]) on screen triangle
  // tris[i]. known(px, py, footprints, albedo) may supply the albedos (true) instead.
  auto shade_four = [&](const int* tris, const int* px, const int* py, auto&& known,
                        Vector3f* out) {
    std::array<float, 4> footprint;
    std::array<Vector3f, 4> scale, offset;
    for (int i = 0; i < 4; ++i) {
      const SurfacePoint sp = surface_at(screen_tris[tris[i]], px[i] + 0.5f, py[i] + 0.5f);
      const auto lighting = lighting_at(sp);
      scale[i] = lighting.scale;
      offset[i] = lighting.offset;
      footprint[i] = sp.footprint_m;
    }
    std::array<Vector3f, 4> albedo;
    if (!known(px, py, footprint.data(), albedo.data())) {
      albedo_batch(tris, px, py, 4, footprint.data(), albedo.data());
    }
    for (int i = 0; i < 4; ++i) out[i] = albedo[i].cwiseProduct(scale[i]) + offset[i];
  };
  // Studio triangles without a texture: one colour over a plane, lit smoothly.
  auto plain_studio = [&](const ScreenTriangle& t) {
    return t.source >= object_tris && studio.materials[source_of(t).material()].texture < 0;
  };
  // Two studio triangles of one material on one plane (their face normals agree).
  auto same_studio_plane = [&](const ScreenTriangle& a, const ScreenTriangle& b) {
    const SourceTriangle sa = source_of(a), sb = source_of(b);
    return sa.material() == sb.material() &&
           room.face_normals[sa.local].dot(room.face_normals[sb.local]) >= kQuadNormalCos;
  };
  // A plain studio plane's radiance at (px, py), which may lie outside the triangle.
  auto shade_on_plane = [&](const ScreenTriangle& s, float px, float py) -> Vector3f {
    const SurfacePoint sp = surface_at(s, px, py, true);
    const Lighting lighting = lighting_at(sp);
    return studio.materials[sp.material].base_color.cwiseProduct(lighting.scale) + lighting.offset;
  };
  auto shade = [&](const ScreenTriangle& s, float px, float py) -> Vector3f {
    const SurfacePoint sp = surface_at(s, px, py);
    const Lighting lighting = lighting_at(sp);
    return albedo_at(s, px, py, sp.footprint_m).cwiseProduct(lighting.scale) + lighting.offset;
  };

  // A pixel's samples grouped into surfaces (same object membership, depths within 1 %): each is
  // shaded once, with the triangle holding most of its samples; only silhouettes blend surfaces.
  struct PixelSurfaces {
    int count = 0;
    std::array<std::int32_t, kSamples> triangle;  // screen triangle shading each surface
    std::array<int, kSamples> samples;            // samples it covers
    int object_samples = 0;
    float nearest = 0;  // largest 1/z
  };
  // A pixel whose samples all hold screen triangle `id` (object_samples: kSamples on the
  // object, 0 on the studio), as group_samples finds it.
  auto single_surface = [](const float* inv_z, std::int32_t id, int object_samples) {
    PixelSurfaces out;
    out.nearest = std::max({inv_z[0], inv_z[1], inv_z[2], inv_z[3]});
    out.count = 1;
    out.triangle[0] = id;
    out.samples[0] = kSamples;
    out.object_samples = object_samples;
    return out;
  };
  auto group_samples = [&](const float* inv_z, const std::int32_t* tri) {
    if (tri[0] >= 0 && tri[0] == tri[1] && tri[0] == tri[2] && tri[0] == tri[3]) {
      // Inside one triangle, as most pixels are.
      return single_surface(inv_z, tri[0], screen_tris[tri[0]].source < object_tris ? kSamples : 0);
    }
    PixelSurfaces out;
    std::array<int, kSamples> surface{-1, -1, -1, -1};
    for (int k = 0; k < kSamples; ++k) {
      const std::int32_t id = tri[k];
      out.nearest = std::max(out.nearest, inv_z[k]);
      if (id < 0 || surface[k] >= 0) continue;
      const bool on_object = screen_tris[id].source < object_tris;
      int count = 0;
      for (int j = k; j < kSamples; ++j) {
        const std::int32_t other = tri[j];
        if (other < 0 || surface[j] >= 0) continue;
        if ((screen_tris[other].source < object_tris) != on_object) continue;
        if (std::abs(inv_z[j] - inv_z[k]) > 0.01f * inv_z[k]) continue;
        surface[j] = k;
        ++count;
      }
      int best = k, best_votes = 0;
      for (int j = k; j < kSamples; ++j) {
        if (surface[j] != k) continue;
        int votes = 0;
        for (int m = k; m < kSamples; ++m) votes += surface[m] == k && tri[m] == tri[j];
        if (votes > best_votes) {
          best = j;
          best_votes = votes;
        }
      }
      if (on_object) out.object_samples += count;
      out.triangle[out.count] = tri[best];
      out.samples[out.count++] = count;
    }
    return out;
  };
  auto write_pixel = [&](int px, int py, const PixelSurfaces& surfaces, const Vector3f& color) {
    const size_t pixel = static_cast<size_t>(py) * canvas.width + px;
    frame.rgb[pixel * 3 + 0] = color.x();
    frame.rgb[pixel * 3 + 1] = color.y();
    frame.rgb[pixel * 3 + 2] = color.z();
    frame.depth_m[pixel] =
        surfaces.nearest > 0 ? 1 / surfaces.nearest : std::numeric_limits<float>::infinity();
    frame.mask[pixel] = surfaces.object_samples * 2 >= kSamples ? 255 : 0;
  };
  auto shade_pixel = [&](int px, int py, const PixelSurfaces& surfaces) {
    Vector3f color = Vector3f::Zero();
    for (int i = 0; i < surfaces.count; ++i) {
      color += shade(screen_tris[surfaces.triangle[i]], px + 0.5f, py + 0.5f) *
               (float(surfaces.samples[i]) / kSamples);
    }
    write_pixel(px, py, surfaces, color);
  };

  const auto raster_start = Clock::now();
  std::atomic<std::int64_t> quads_with_block_albedos{0};
  // The studio is planes of one plain colour: over a 4 x 4 block within one plane the light
  // varies smoothly (soft shadows included), so it is summed at the block's corners and
  // interpolated, corners shared between blocks.
  constexpr int kBlock = 4;
  constexpr int kCorners = kTileSize / kBlock + 1;
  const bool use_blocks = !request.per_pixel_lighting;
  // Where 8 pixels subtend under 1.5 mrad (the full-resolution frames of a normal lens), the
  // studio planes are shaded every 8 pixels: their light, soft shadows included, does not bend
  // over that span, and the green screen and the turntable fill most of a frame.
  const bool coarse_corners = use_blocks && 2 * kBlock / fx <= 1.5e-3f;
  // Where 16 pixels subtend under 2.5 mrad, the plane is first shaded every 16 pixels; a 16 px
  // cell whose four corners agree within kWideCellTolerance (relative, per channel) is
  // interpolated from them, any other is shaded every 8 pixels as above. Light falling off over a
  // plane changes far less than that across 16 px; a shadow edge or a penumbra changes more.
  const bool wide_corners = coarse_corners && 4 * kBlock / fx <= 2.5e-3f;
  constexpr float kWideCellTolerance = 0.01f;
  // And where 32 pixels (a tile) subtend under 5 mrad, the same one level up: the plane is first
  // shaded at the tiles' corners, and a tile whose corners agree within kTileCellTolerance takes
  // its 16 px corners from them (the full-resolution frames of a normal lens, whose green screen
  // is mostly such tiles). Half the cells' tolerance: a curve's departure from the blend grows
  // with the square of the cell's size.
  const bool tile_corners = wide_corners && 8 * kBlock / fx <= 5e-3f;
  constexpr float kTileCellTolerance = 0.005f;
  // Whether a cell's four corner radiances agree within `tolerance` (relative, per channel).
  auto corners_agree = [](const Vector3f& c00, const Vector3f& c10, const Vector3f& c01,
                          const Vector3f& c11, float tolerance) {
    const Vector3f lo = c00.cwiseMin(c10).cwiseMin(c01).cwiseMin(c11);
    const Vector3f hi = c00.cwiseMax(c10).cwiseMax(c01).cwiseMax(c11);
    return ((hi - lo).array() <= tolerance * hi.array()).all();
  };
  // Radiance at the corners of a tile's 4 x 4 blocks on a plain studio plane, cached per tile
  // and plane. On the plane: unclamped barycentrics reach past the triangle's edges along it.
  struct PlaneCorners {
    // One corner of padding: a row's last corner is read as four floats.
    std::array<Vector3f, kCorners * kCorners + 1> color;
    std::array<std::int32_t, kCorners * kCorners> plane;  // source triangle, -1: not yet
    PlaneCorners() { plane.fill(-1); }
  };
  // Corner (cx, cy) of the grid of the tile at (x0, y0). With coarse corners only the even ones
  // are shaded and odd ones are the mean of their even neighbours; with wide corners the even
  // ones come from the 16 px cell's corners where those agree.
  auto plane_corner_of = [&](auto&& self, PlaneCorners& cache, const ScreenTriangle& plane, int x0,
                             int y0, int cx, int cy) -> Vector3f {
    const int slot = cy * kCorners + cx;
    if (cache.plane[slot] == plane.source) return cache.color[slot];
    auto at = [&](int ax, int ay) { return self(self, cache, plane, x0, y0, ax, ay); };
    Vector3f color;
    // Interpolated within the cell whose corners are (ax, ay) and (bx, by) when those agree
    // within `tolerance` (relative, per channel); shaded otherwise.
    auto from_cell = [&](int ax, int bx, int ay, int by, int cell, float tolerance) {
      const Vector3f c00 = at(ax, ay), c10 = at(bx, ay), c01 = at(ax, by), c11 = at(bx, by);
      if (corners_agree(c00, c10, c01, c11, tolerance)) {
        const float tx = static_cast<float>(cx % cell) / static_cast<float>(cell);
        const float ty = static_cast<float>(cy % cell) / static_cast<float>(cell);
        return Vector3f((1 - ty) * ((1 - tx) * c00 + tx * c10) + ty * ((1 - tx) * c01 + tx * c11));
      }
      return shade_on_plane(plane, static_cast<float>(x0 + kBlock * cx),
                            static_cast<float>(y0 + kBlock * cy));
    };
    if (tile_corners && cx % 4 == 0 && cy % 4 == 0 && (cx % 8 || cy % 8)) {
      // A corner on a tile's edge looks at that edge's two ends only, as below.
      const int ax = cx - cx % 8, bx = cx % 8 ? ax + 8 : ax;
      const int ay = cy - cy % 8, by = cy % 8 ? ay + 8 : ay;
      color = from_cell(ax, bx, ay, by, 8, kTileCellTolerance);
    } else if (wide_corners && cx % 2 == 0 && cy % 2 == 0 && (cx % 4 || cy % 4)) {
      // A corner on a 16 px cell's edge looks at that edge's two ends only (all that its
      // interpolation uses), so the tiles on both sides of a tile border decide alike.
      const int ax = cx - cx % 4, bx = cx % 4 ? ax + 4 : ax;
      const int ay = cy - cy % 4, by = cy % 4 ? ay + 4 : ay;
      color = from_cell(ax, bx, ay, by, 4, kWideCellTolerance);
    } else if (coarse_corners && (cx % 2 || cy % 2)) {
      const int ax = cx - cx % 2, bx = cx + cx % 2;
      const int ay = cy - cy % 2, by = cy + cy % 2;
      color = 0.25f * (at(ax, ay) + at(bx, ay) + at(ax, by) + at(bx, by));
    } else {
      color = shade_on_plane(plane, static_cast<float>(x0 + kBlock * cx),
                             static_cast<float>(y0 + kBlock * cy));
    }
    cache.plane[slot] = plane.source;
    cache.color[slot] = color;
    return color;
  };
  auto plane_corner = [&](PlaneCorners& cache, const ScreenTriangle& plane, int x0, int y0, int cx,
                          int cy) {
    return plane_corner_of(plane_corner_of, cache, plane, x0, y0, cx, cy);
  };
  // A tile inside one plain studio triangle that nothing else in its bin touches: every sample
  // is that plane, so the tile is its blocks' interpolated corners, the depth the plane's
  // nearest sample per pixel and the mask empty, without the per-sample buffers.
  auto plain_studio_tile = [&](int x0, int y0, int x1, int y1, std::int32_t id) -> bool {
    const ScreenTriangle& plane = screen_tris[id];
    if (!use_blocks || !plain_studio(plane)) return false;
    PlaneCorners cache;
    const int columns = (x1 - x0 + kBlock - 1) / kBlock, rows = (y1 - y0 + kBlock - 1) / kBlock;
    // The tile this thread did just before, when it is the left neighbour on the same screen
    // triangle: its right column of corners is this tile's left one, the same values (a corner
    // on a tile's border depends on that border's corners only, see plane_corner_of).
    struct RightColumn {
      std::uint64_t frame = 0;
      int x1 = -1, y0 = -1;
      std::int32_t triangle = -1;
      std::array<Vector3f, kCorners> color;
    };
    thread_local RightColumn left;
    if (left.frame == frame_serial && left.x1 == x0 && left.y0 == y0 && left.triangle == id) {
      for (int cy = 0; cy <= rows; ++cy) {
        cache.plane[cy * kCorners] = plane.source;
        cache.color[cy * kCorners] = left.color[cy];
      }
    }
    // A whole tile whose four corners agree is smooth: every corner inside it would come out as
    // their bilinear blend (the 16 px and 8 px corners from agreeing cells, the odd ones as
    // means of those), so the inner ones are blended straight from the four. The left and right
    // columns, which the tiles beside it share (see RightColumn), still follow the rule they do
    // there. The top and bottom rows are blended too: a tile above or below that is not smooth
    // reaches the same values by the rule's steps, which may round an ulp apart (the seam is
    // 1e-7 of the light; it does not depend on which thread draws which tile).
    bool smooth = false;
    if (tile_corners && columns == kCorners - 1 && rows == kCorners - 1) {
      constexpr int kLast = kCorners - 1;
      const Vector3f c00 = plane_corner(cache, plane, x0, y0, 0, 0);
      const Vector3f c10 = plane_corner(cache, plane, x0, y0, kLast, 0);
      const Vector3f c01 = plane_corner(cache, plane, x0, y0, 0, kLast);
      const Vector3f c11 = plane_corner(cache, plane, x0, y0, kLast, kLast);
      smooth = corners_agree(c00, c10, c01, c11, kTileCellTolerance);
      if (smooth) {
        for (int cy = 0; cy <= kLast; ++cy) {
          plane_corner(cache, plane, x0, y0, 0, cy);
          plane_corner(cache, plane, x0, y0, kLast, cy);
          const float ty = static_cast<float>(cy) / kLast;
          const Vector3f row_left = (1 - ty) * c00 + ty * c01;
          const Vector3f row_right = (1 - ty) * c10 + ty * c11;
          for (int cx = 1; cx < kLast; ++cx) {
            const float tx = static_cast<float>(cx) / kLast;
            const int slot = cy * kCorners + cx;
            cache.color[slot] = (1 - tx) * row_left + tx * row_right;
            cache.plane[slot] = plane.source;
          }
        }
      }
    }
    for (int cy = 0; cy <= rows && !smooth; ++cy) {
      for (int cx = 0; cx <= columns; ++cx) plane_corner(cache, plane, x0, y0, cx, cy);
    }
    left.frame = frame_serial;
    left.x1 = columns == kTileSize / kBlock ? x1 : -1;
    left.y0 = y0;
    left.triangle = id;
    for (int cy = 0; cy <= rows; ++cy) left.color[cy] = cache.color[cy * kCorners + columns];
    // 1/z is affine over the plane, so in every pixel the nearest of the four samples is the
    // one furthest along its gradient: one sample per pixel, eight pixels at a time.
    int near_sample = 0;
    for (int k = 1; k < kSamples; ++k) {
      auto along = [&](int j) {
        return plane.inv_z_plane[0] * kSampleX[j] + plane.inv_z_plane[1] * kSampleY[j];
      };
      if (along(k) > along(near_sample)) near_sample = k;
    }
    const Float8 pixel_x = kTexelCentres - 0.5f;  // 0, 1, ..., 7
    const Float8 infinity = Float8{} + std::numeric_limits<float>::infinity();
    for (int py = y0; py < y1; ++py) {
      const int cy = (py - y0) / kBlock;
      const float fy = ((py - y0) % kBlock + 0.5f) / kBlock;
      float* rgb = &frame.rgb[3 * (static_cast<std::size_t>(py) * canvas.width + x0)];
      float* depth = &frame.depth_m[static_cast<std::size_t>(py) * canvas.width + x0];
      std::fill_n(&frame.mask[static_cast<std::size_t>(py) * canvas.width + x0], x1 - x0, 0);
      // Whole blocks: their four pixels' twelve values, blended from the two corners' colours
      // repeated across three four-lane registers (the per-pixel arithmetic of the loop below).
      const int whole_blocks = (x1 - x0) / kBlock;
      static_assert(kBlock == 4, "a block's twelve values are three four-lane registers");
      static constexpr Float4 kWeight[3] = {{0.125f, 0.125f, 0.125f, 0.375f},
                                            {0.375f, 0.375f, 0.625f, 0.625f},
                                            {0.625f, 0.875f, 0.875f, 0.875f}};
      static constexpr Int4 kChannel[3] = {{0, 1, 2, 0}, {1, 2, 0, 1}, {2, 0, 1, 2}};
      // The corners' rows read directly: loading four floats just stored as three stalls.
      const float* upper_row = cache.color[cy * kCorners].data();
      const float* lower_row = cache.color[(cy + 1) * kCorners].data();
      auto edge_at = [&](int cx) {
        return fy * load4(lower_row + 3 * cx) + (1 - fy) * load4(upper_row + 3 * cx);
      };
      for (int cx = 0; cx < whole_blocks; ++cx) {
        const Float4 left = edge_at(cx), right = edge_at(cx + 1);
        for (int k = 0; k < 3; ++k) {
          const Float4 from = __builtin_shuffle(left, kChannel[k]);
          const Float4 to = __builtin_shuffle(right, kChannel[k]);
          store4(rgb + 3 * kBlock * cx + 4 * k, kWeight[k] * to + (1 - kWeight[k]) * from);
        }
      }
      // A last, partial block (the canvas's right edge): pixel by pixel.
      for (int px = x0 + kBlock * whole_blocks; px < x1; ++px) {
        const int cx = (px - x0) / kBlock;
        const float fx = ((px - x0) % kBlock + 0.5f) / kBlock;
        const Float4 left = edge_at(cx), right = edge_at(cx + 1);
        const Float4 color = fx * right + (1 - fx) * left;
        float* out = rgb + 3 * (px - x0);
        for (int c = 0; c < 3; ++c) out[c] = color[c];
      }
      // The nearest sample's 1/z, as the visibility pass computes it.
      const float iz_row = plane.inv_z_plane[1] * (static_cast<float>(py) + kSampleY[near_sample]);
      for (int px = x0; px < x1; px += 8) {
        const Float8 sx = (static_cast<float>(px) + pixel_x) + kSampleX[near_sample];
        const Float8 nearest = plane.inv_z_plane[0] * sx + iz_row + plane.inv_z_plane[2];
        const Float8 z = nearest > 0 ? 1 / nearest : infinity;
        if (x1 - px >= 8) {
          std::memcpy(depth + (px - x0), &z, sizeof z);  // a fixed size: no library call
        } else {
          std::memcpy(depth + (px - x0), &z, (x1 - px) * sizeof(float));
        }
      }
    }
    return true;
  };
  auto plain_studio_tile_recorded = [&](int x0, int y0, int x1, int y1, std::int32_t id) {
    if (!plain_studio_tile(x0, y0, x1, y1, id)) return false;
    record_ranges(x0, y0, x1, y1);
    return true;
  };
  // The studio's convex planar faces (quads, the discs' caps), for the tiles they cover together.
  auto face_of = [&](const ScreenTriangle& t) -> std::int32_t {
    if (t.source < object_tris) return -1;
    const auto local = static_cast<std::size_t>(t.source - object_tris);
    return local < room.convex_face.size() ? room.convex_face[local] : -1;
  };
  rasterize_tiles<kSamples>(
      setup, canvas, face_of, plain_studio_tile_recorded,
      [&](int x0, int y0, int x1, int y1, const float* inv_z, const std::int32_t* tri) {
        auto at = [&](int px, int py) { return ((py - y0) * kTileSize + (px - x0)) * kSamples; };
        // 2 x 2 quads inside one surface sum the lights once, at the quad's centre, and take the
        // albedo (texture, pattern) per pixel: lighting varies slowly across two pixels, the
        // surface's detail does not. Quads that hold an edge, and odd last rows and columns, are
        // shaded pixel by pixel.
        // A bumpy block that failed its light check (shade_object_block) leaves its sixteen
        // albedos here for its quads: the same pixels, triangles and sample points. Of an
        // albedo only the pattern's fade depends on the footprint, and where the block's and the
        // quad's footprints both leave the pattern fully resolved, the albedos are the quad's.
        struct BlockAlbedos {
          bool valid = false;
          int bx = 0, by = 0;
          float footprint_m = 0;
          const ir::SurfacePattern* pattern = nullptr;  // the block's material's
          std::array<Vector3f, kBlock * kBlock> albedo;
        } failed_block;
        std::int64_t tile_quads_with_block_albedos = 0;  // summed once per tile (a shared counter)
        auto known_albedos = [&](const int* px, const int* py, const float* footprints,
                                 Vector3f* out) {
          if (!failed_block.valid || !request.reuse_block_albedos) return false;
          const ir::SurfacePattern& pattern = *failed_block.pattern;
          if (!scene::pattern_fully_resolved(pattern, failed_block.footprint_m)) return false;
          for (int i = 0; i < 4; ++i) {
            if (!scene::pattern_fully_resolved(pattern, footprints[i])) return false;
          }
          for (int i = 0; i < 4; ++i) {
            out[i] =
                failed_block.albedo[(py[i] - failed_block.by) * kBlock + px[i] - failed_block.bx];
          }
          ++tile_quads_with_block_albedos;
          return true;
        };
        auto resolve_quad = [&](int qx, int qy) {
          const bool whole = qx + 1 < x1 && qy + 1 < y1 && !request.per_pixel_lighting;
          std::array<PixelSurfaces, 4> quad;
          bool uniform = whole;
          for (int i = 0; i < 4 && (whole || i == 0); ++i) {
            const int px = qx + (i & 1), py = qy + (i >> 1);
            if (px >= x1 || py >= y1) continue;
            quad[i] = group_samples(inv_z + at(px, py), tri + at(px, py));
            uniform = uniform && quad[i].count == 1 && quad[i].samples[0] == kSamples;
          }
          if (uniform) {
            const ScreenTriangle& first = screen_tris[quad[0].triangle[0]];
            const bool on_object = first.source < object_tris;
            for (int i = 1; i < 4 && uniform; ++i) {
              const ScreenTriangle& other = screen_tris[quad[i].triangle[0]];
              uniform = (other.source < object_tris) == on_object &&
                        source_of(other).material() == source_of(first).material() &&
                        std::abs(quad[i].nearest - quad[0].nearest) <= 0.01f * quad[0].nearest;
            }
          }
          if (!uniform) {
            for (int i = 0; i < 4; ++i) {
              const int px = qx + (i & 1), py = qy + (i >> 1);
              if (px >= x1 || py >= y1) continue;
              if (!whole) quad[i] = group_samples(inv_z + at(px, py), tri + at(px, py));
              shade_pixel(px, py, quad[i]);
            }
            return;
          }
          const ScreenTriangle& first = screen_tris[quad[0].triangle[0]];
          SurfacePoint centre = surface_at(first, qx + 1.0f, qy + 1.0f);
          const scene::ShadedMaterial& material = studio.materials[centre.material];
          bool flat = plain_studio(first);
          for (int i = 1; i < 4 && flat; ++i) {
            flat = same_studio_plane(screen_tris[quad[i].triangle[0]], first);
          }
          if (flat) {
            // Studio surfaces are plain planes: one colour for a quad within one of them.
            const Lighting lighting = lighting_at(centre);
            const Vector3f color =
                material.base_color.cwiseProduct(lighting.scale) + lighting.offset;
            for (int i = 0; i < 4; ++i) write_pixel(qx + (i & 1), qy + (i >> 1), quad[i], color);
            return;
          }
          // Otherwise the lights are summed once, at the quad's centre, when the four pixels'
          // shading normals agree with its normal (a smooth patch), else per pixel.
          bool smooth = true;
          for (int i = 0; i < 4 && smooth; ++i) {
            smooth = normal_agrees(screen_tris[quad[i].triangle[0]], qx + (i & 1) + 0.5f,
                                   qy + (i >> 1) + 0.5f, centre);
          }
          std::array<int, 4> tris, pxs, pys;
          for (int i = 0; i < 4; ++i) {
            tris[i] = quad[i].triangle[0];
            pxs[i] = qx + (i & 1);
            pys[i] = qy + (i >> 1);
          }
          if (smooth) {
            const Lighting lighting = lighting_at(centre);
            std::array<Vector3f, 4> albedo;
            const std::array<float, 4> footprints = {centre.footprint_m, centre.footprint_m,
                                                     centre.footprint_m, centre.footprint_m};
            if (!known_albedos(pxs.data(), pys.data(), footprints.data(), albedo.data())) {
              albedo_batch(tris.data(), pxs.data(), pys.data(), 4, centre.footprint_m,
                           albedo.data());
            }
            for (int i = 0; i < 4; ++i) {
              write_pixel(pxs[i], pys[i], quad[i],
                          albedo[i].cwiseProduct(lighting.scale) + lighting.offset);
            }
            return;
          }
          // A bumpy patch: each pixel lit on its own; the albedos (the pattern) in one batch.
          std::array<Vector3f, 4> colors;
          shade_four(tris.data(), pxs.data(), pys.data(), known_albedos, colors.data());
          for (int i = 0; i < 4; ++i) write_pixel(pxs[i], pys[i], quad[i], colors[i]);
        };
        PlaneCorners corners;
        // The object's corners: lighting (albedo applied per pixel) and shading normal.
        struct ObjectCorner {
          Lighting lighting;
          Vector3f n;
          float footprint_m;
          bool known = false;
        };
        std::array<ObjectCorner, kCorners * kCorners> object_corner;
        // A 4 x 4 block inside one smooth patch of the object: the lights are summed at the
        // block's corners (shared with the neighbouring blocks) and interpolated, the albedo
        // taken per pixel; the block must be one material, one surface per pixel, without
        // depth steps, and its corner normals within kBlockNormalCos of each other (or within
        // kBlockBumpyNormalCos and its light nearly linear). False (and nothing written)
        // otherwise.
        // `single_id`: the screen triangle that holds all of the block's samples, if one does
        // (-1 otherwise); its pixels then need no grouping and its material no lookup per pixel.
        auto shade_object_block = [&](int bx, int by, std::int32_t single_id) -> bool {
          failed_block.valid = false;
          std::array<PixelSurfaces, kBlock * kBlock> block;
          int material = -1;
          if (single_id >= 0) {
            if (screen_tris[single_id].source >= object_tris) return false;
            material = source_of(screen_tris[single_id]).material();
          }
          for (int i = 0; i < kBlock * kBlock; ++i) {
            const int px = bx + i % kBlock, py = by + i / kBlock;
            if (single_id >= 0) {
              block[i] = single_surface(inv_z + at(px, py), single_id, kSamples);
            } else {
              block[i] = group_samples(inv_z + at(px, py), tri + at(px, py));
            }
            const PixelSurfaces& b = block[i];
            if (single_id < 0) {
              if (b.count != 1 || b.samples[0] != kSamples || b.object_samples != kSamples) {
                return false;
              }
              const int m = source_of(screen_tris[b.triangle[0]]).material();
              if (i == 0) material = m;
              if (m != material) return false;
            }
            if (std::abs(b.nearest - block[0].nearest) > 0.01f * block[0].nearest) return false;
          }
          std::array<const ObjectCorner*, 4> corner;
          for (int k = 0; k < 4; ++k) {
            const int cx = (bx - x0) / kBlock + (k & 1), cy = (by - y0) / kBlock + (k >> 1);
            ObjectCorner& c = object_corner[cy * kCorners + cx];
            if (!c.known) {
              // On the plane of the triangle under the block's pixel at this corner.
              const int pixel = (k >> 1) * (kBlock - 1) * kBlock + (k & 1) * (kBlock - 1);
              const SurfacePoint sp = surface_at(screen_tris[block[pixel].triangle[0]],
                                                 static_cast<float>(bx + kBlock * (k & 1)),
                                                 static_cast<float>(by + kBlock * (k >> 1)), true);
              c.lighting = lighting_at(sp);
              c.n = sp.n;
              c.footprint_m = sp.footprint_m;
              c.known = true;
            }
            corner[k] = &c;
          }
          bool smooth = true;
          for (int k = 0; k < 4; ++k) {
            for (int m = k + 1; m < 4; ++m) {
              const float cos_angle = corner[k]->n.dot(corner[m]->n);
              if (cos_angle < kBlockBumpyNormalCos) return false;
              smooth = smooth && cos_angle >= kBlockNormalCos;
            }
          }
          std::array<int, kBlock * kBlock> tris, pxs, pys;
          std::array<Vector3f, kBlock * kBlock> albedo;
          for (int i = 0; i < kBlock * kBlock; ++i) {
            tris[i] = block[i].triangle[0];
            pxs[i] = bx + i % kBlock;
            pys[i] = by + i / kBlock;
          }
          albedo_batch(tris.data(), pxs.data(), pys.data(), kBlock * kBlock, corner[0]->footprint_m,
                       albedo.data());
          if (!smooth) {
            // Corner normals apart (kBlockBumpyNormalCos): the lights summed at the block's
            // centre against the corners' mean, for the block's mean albedo. Where the light
            // bends inside the block (a penumbra, a highlight, a crease), the bilinear fill
            // would miss it, and the block is shaded in quads.
            const int centre_pixel = (kBlock / 2) * kBlock + kBlock / 2;
            const SurfacePoint sp = surface_at(screen_tris[block[centre_pixel].triangle[0]],
                                               static_cast<float>(bx + kBlock / 2),
                                               static_cast<float>(by + kBlock / 2), true);
            const Lighting exact = lighting_at(sp);
            Vector3f mean_albedo = Vector3f::Zero();
            for (const Vector3f& a : albedo) mean_albedo += a;
            mean_albedo /= kBlock * kBlock;
            Vector3f scale = Vector3f::Zero(), offset = Vector3f::Zero();
            for (int k = 0; k < 4; ++k) {
              scale += 0.25f * corner[k]->lighting.scale;
              offset += 0.25f * corner[k]->lighting.offset;
            }
            const Vector3f want = mean_albedo.cwiseProduct(exact.scale) + exact.offset;
            const Vector3f have = mean_albedo.cwiseProduct(scale) + offset;
            if (((have - want).cwiseAbs().array() > kBlockLightTolerance * want.array()).any()) {
              failed_block.valid = true;
              failed_block.bx = bx;
              failed_block.by = by;
              failed_block.footprint_m = corner[0]->footprint_m;
              failed_block.pattern = &studio.materials[material].pattern;
              failed_block.albedo = albedo;
              return false;
            }
          }
          for (int i = 0; i < kBlock * kBlock; ++i) {
            const float fx = (i % kBlock + 0.5f) / kBlock, fy = (i / kBlock + 0.5f) / kBlock;
            const float w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
            Vector3f scale = Vector3f::Zero(), offset = Vector3f::Zero();
            for (int k = 0; k < 4; ++k) {
              scale += w[k] * corner[k]->lighting.scale;
              offset += w[k] * corner[k]->lighting.offset;
            }
            write_pixel(pxs[i], pys[i], block[i], albedo[i].cwiseProduct(scale) + offset);
          }
          return true;
        };
        for (int by = y0; by < y1; by += kBlock) {
          for (int bx = x0; bx < x1; bx += kBlock) {
            bool flat_block = use_blocks && bx + kBlock <= x1 && by + kBlock <= y1;
            std::array<PixelSurfaces, kBlock * kBlock> block;
            int plane_triangle = -1;  // the screen triangle that stands for the block's plane
            // Most blocks lie inside one studio triangle: every sample holds the same id.
            bool one_triangle = flat_block;
            const std::int32_t first_id = flat_block ? tri[at(bx, by)] : -1;
            for (int row = 0; row < kBlock && one_triangle; ++row) {
              const std::int32_t* ids = tri + at(bx, by + row);
              std::int32_t differ = 0;
              for (int k = 0; k < kBlock * kSamples; ++k) differ |= ids[k] ^ first_id;
              one_triangle = differ == 0;
            }
            const std::int32_t single_id = one_triangle ? first_id : -1;
            if (one_triangle && first_id >= 0 && plain_studio(screen_tris[first_id])) {
              for (int i = 0; i < kBlock * kBlock; ++i) {
                block[i] =
                    single_surface(inv_z + at(bx + i % kBlock, by + i / kBlock), first_id, 0);
              }
              plane_triangle = first_id;
            } else {
              one_triangle = false;
            }
            for (int i = 0; i < kBlock * kBlock && flat_block && !one_triangle; ++i) {
              const int px = bx + i % kBlock, py = by + i / kBlock;
              block[i] = group_samples(inv_z + at(px, py), tri + at(px, py));
              const PixelSurfaces& b = block[i];
              if (b.count != 1 || b.samples[0] != kSamples) {
                flat_block = false;
                break;
              }
              const ScreenTriangle& t = screen_tris[b.triangle[0]];
              if (i == 0) {
                plane_triangle = b.triangle[0];
                flat_block = plain_studio(t);
                continue;
              }
              flat_block = plain_studio(t) && same_studio_plane(t, screen_tris[plane_triangle]) &&
                           std::abs(b.nearest - block[0].nearest) <= 0.02f * block[0].nearest;
            }
            if (!flat_block && use_blocks && bx + kBlock <= x1 && by + kBlock <= y1 &&
                shade_object_block(bx, by, single_id)) {
              continue;
            }
            if (!flat_block) {
              for (int qy = by; qy < std::min(y1, by + kBlock); qy += 2) {
                for (int qx = bx; qx < std::min(x1, bx + kBlock); qx += 2) resolve_quad(qx, qy);
              }
              failed_block.valid = false;  // its albedos served these quads only
              continue;
            }
            // Radiance at the block's corners, on the plane (unclamped barycentrics reach
            // past the triangle's edges along the plane).
            const ScreenTriangle& plane = screen_tris[plane_triangle];
            std::array<Vector3f, 4> corner;
            for (int k = 0; k < 4; ++k) {
              corner[k] = plane_corner(corners, plane, x0, y0, (bx - x0) / kBlock + (k & 1),
                                       (by - y0) / kBlock + (k >> 1));
            }
            for (int i = 0; i < kBlock * kBlock; ++i) {
              const int px = bx + i % kBlock, py = by + i / kBlock;
              const float fx = (i % kBlock + 0.5f) / kBlock, fy = (i / kBlock + 0.5f) / kBlock;
              const Vector3f color = (1 - fy) * ((1 - fx) * corner[0] + fx * corner[1]) +
                                     fy * ((1 - fx) * corner[2] + fx * corner[3]);
              write_pixel(px, py, block[i], color);
            }
          }
        }
        if (tile_quads_with_block_albedos > 0) {
          quads_with_block_albedos.fetch_add(tile_quads_with_block_albedos,
                                             std::memory_order_relaxed);
        }
        record_ranges(x0, y0, x1, y1);
      });
  if (timings) {
    timings->raster_ms += ms_since(raster_start);
    timings->quads_with_block_albedos += quads_with_block_albedos.load();
  }
  return frame;
}

}  // namespace rigc::raster

namespace rigc::raster {

Eigen::Vector3f light_illuminance(const ir::Light& light, const Eigen::Vector3f& point,
                                  const Eigen::Vector3f& normal) {
  LightSample sample;
  if (!sample_light(FrameLight(light, light.color.cast<float>()), point, &sample)) {
    return Vector3f::Zero();
  }
  return sample.illuminance * std::max(0.0f, normal.dot(sample.to_light));
}

VisibilityBuffer render_visibility(const ir::Scene& scene, const scene::StudioScene& studio,
                                   const FrameRequest& request) {
  const FrameContext context(scene, studio, request);
  const ScreenSetup setup = context.setup(request.canvas);
  VisibilityBuffer buffer;
  buffer.width = request.canvas.width;
  buffer.height = request.canvas.height;
  const size_t pixel_count = static_cast<size_t>(buffer.width) * buffer.height;
  buffer.object_triangle.assign(pixel_count, -1);
  buffer.depth_m.assign(pixel_count, std::numeric_limits<float>::infinity());
  rasterize_pixels<1>(setup, request.canvas,
                      [&](int px, int py, const float* inv_z, const std::int32_t* tri) {
                        if (tri[0] < 0) return;
                        const size_t pixel = static_cast<size_t>(py) * buffer.width + px;
                        buffer.depth_m[pixel] = 1 / inv_z[0];
                        const int source = setup.tris[tri[0]].source;
                        if (source < context.object_tris) buffer.object_triangle[pixel] = source;
                      });
  return buffer;
}

std::vector<float> render_face_colors(const ir::Scene& scene, const scene::StudioScene& studio,
                                      const FrameRequest& request,
                                      const std::vector<Eigen::Vector3f>& face_colors) {
  const FrameContext context(scene, studio, request);
  const ScreenSetup setup = context.setup(request.canvas);
  std::vector<float> rgb(static_cast<size_t>(request.canvas.width) * request.canvas.height * 3,
                         0.08f);
  // Face normals lit by a headlight, so the shape reads in the picture. The view direction is
  // the pixel's own ray: one per face (its centroid's) striped planes made of thin triangles.
  const dslr::Intrinsics& canvas = request.canvas;
  const Matrix3f world_from_camera_rot = context.cam_rot.transpose();
  rasterize_pixels<kSamples>(
      setup, canvas, [&](int px, int py, const float*, const std::int32_t* tri) {
        const Vector3f ray(static_cast<float>((px + 0.5 - canvas.cx) / canvas.fx),
                           static_cast<float>((py + 0.5 - canvas.cy) / canvas.fy), 1.0f);
        const Vector3f view = (world_from_camera_rot * ray).normalized();
        Vector3f color = Vector3f::Zero();
        for (int k = 0; k < kSamples; ++k) {
          if (tri[k] < 0) {
            color += Vector3f::Constant(0.08f);
            continue;
          }
          const int t = setup.tris[tri[k]].source;
          const Vector3f a = context.world_vertex(t, 0), b = context.world_vertex(t, 1),
                         c = context.world_vertex(t, 2);
          const Vector3f normal = (b - a).cross(c - a).normalized();
          const float light = 0.35f + 0.65f * std::abs(normal.dot(view));
          const Vector3f base = t < context.object_tris && t < static_cast<int>(face_colors.size())
                                    ? face_colors[t]
                                    : Vector3f(0.35f, 0.35f, 0.35f);
          color += base * light;
        }
        color /= kSamples;
        const size_t pixel = (static_cast<size_t>(py) * canvas.width + px) * 3;
        rgb[pixel] = color.x();
        rgb[pixel + 1] = color.y();
        rgb[pixel + 2] = color.z();
      });
  return rgb;
}

}  // namespace rigc::raster
