#include "raster/shadow_map.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "dslr/buffer_pool.h"

namespace rigc::raster {
namespace {

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

// Shadow casters for one frame: world positions and the triangles over them.
struct CasterMesh {
  std::vector<Vector3f> positions;
  const std::vector<std::array<std::uint32_t, 3>>* triangles = nullptr;
  std::size_t first_closed = 0;  // triangles from here on bound solids: back faces skipped
};

// One row of a coarser shadow-map level from two rows of the finer one, `finer_size` texels (an
// odd last column alone): per texel, the nearest depth of its 2 x 2 and the fraction of them
// that hold a caster. At level 0 (`top_held` and `bottom_held` null) a caster is a finite depth.
// (Seven parameters: two rows in and one out, each plane on its own, in a loop over rows.)
void halve_rows(const float* top, const float* bottom, const float* top_held,
                const float* bottom_held, int finer_size, float* nearest, float* held) {
  const float inf = std::numeric_limits<float>::infinity();
  const Float8 one = Float8{} + 1.0f, none = {};
  // The even and the odd lanes of sixteen (GCC 12 and clang both have __builtin_shufflevector).
  auto even_lanes = [](Float8 a, Float8 b) -> Float8 {
    return __builtin_shufflevector(a, b, 0, 2, 4, 6, 8, 10, 12, 14);
  };
  auto odd_lanes = [](Float8 a, Float8 b) -> Float8 {
    return __builtin_shufflevector(a, b, 1, 3, 5, 7, 9, 11, 13, 15);
  };
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
    const Float8 even = even_lanes(near0, near1);
    const Float8 odd = odd_lanes(near0, near1);
    const Float8 out = even < odd ? even : odd;
    const Float8 held0 = held8(x), held1 = held8(x + 8);
    const Float8 fraction = (even_lanes(held0, held1) + odd_lanes(held0, held1)) * 0.25f;
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

// A caster vertex in map texels, with its depth key (see CasterPlanes).
struct LightVertex {
  Vector2f s;
  float key;
  bool behind;
};

// Every vertex into light space once (vertices are shared by about six triangles).
std::vector<LightVertex> light_vertices_of(const ShadowMap& map, const CasterMesh& casters) {
  const int size = map.size;
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
  return light_vertices;
}

// The caster triangles in the map. Rasterized as a key that grows towards the light, one plane
// per triangle: -z for orthographic maps (z is affine in screen space) and 1/z for perspective
// ones. Converted to z at the end.
struct CasterPlanes {
  struct Projected {
    std::array<float, 3> w0_plane, w1_plane, key_plane;
    std::uint16_t x0, y0, x1, y1;
  };
  std::vector<Projected> projected;
  std::vector<char> keep;  // 0: the triangle leaves no texel (behind, edge-on, off the map, culled)
};

CasterPlanes project_casters(const ShadowMap& map, const CasterMesh& casters) {
  const int size = map.size;
  const auto& tris = *casters.triangles;
  const std::vector<LightVertex> light_vertices = light_vertices_of(map, casters);
  CasterPlanes planes;
  planes.projected.resize(tris.size());
  planes.keep.assign(tris.size(), 0);
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
          CasterPlanes::Projected& p = planes.projected[t];
          // Texel centres at +0.5: texels whose centre can fall inside.
          p.x0 = static_cast<std::uint16_t>(std::max(0.0f, std::floor(min_x - 0.5f)));
          p.y0 = static_cast<std::uint16_t>(std::max(0.0f, std::floor(min_y - 0.5f)));
          p.x1 = static_cast<std::uint16_t>(std::min<float>(size - 1, std::ceil(max_x)));
          p.y1 = static_cast<std::uint16_t>(std::min<float>(size - 1, std::ceil(max_y)));
          ScreenTriangle screen;
          screen.inv_z = key;
          compute_planes(screen, s, 1 / area);
          p.w0_plane = screen.w0_plane;
          p.w1_plane = screen.w1_plane;
          p.key_plane = screen.inv_z_plane;
          planes.keep[t] = 1;
        }
      });
  return planes;
}

constexpr int kBandRows = 32;
// Coarser levels down to 16 texels a side or 2^6 texels of `depth` a texel (taps reaching
// 24 x 64 = 1536 texels, as far as the map is wide).
constexpr int kMostCoarseLevels = 6;

bool wants_level(const ShadowMap& map, int finer_size) {
  return static_cast<int>(map.coarse.size()) < kMostCoarseLevels && finer_size / 2 >= 16;
}

// Rows row0 .. row1 of the map's keys: the nearest key of the band's triangles per texel.
void rasterize_band_keys(ShadowMap& map, const CasterPlanes& planes, const CellBins& bins, int band,
                         int row0, int row1) {
  const int size = map.size;
  float* key_rows = map.depth.data() + static_cast<size_t>(row0) * size;
  const float empty = -std::numeric_limits<float>::infinity();
  std::fill(key_rows, key_rows + static_cast<size_t>(row1 - row0) * size, empty);
  for (std::int32_t i = bins.start[band]; i < bins.start[band + 1]; ++i) {
    const CasterPlanes::Projected& p = planes.projected[bins.items[i]];
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
        const Float8 merged = (inside & (key > current)) ? key : current;
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
}

// The band's blocks' nearest depths, while its rows are in cache (a band is whole blocks high;
// the map is whole groups of eight texels wide).
void band_block_nearest(const ShadowMap& map, int row0, int row1,
                        std::vector<float>& block_nearest) {
  static_assert(kBandRows % ShadowMap::kBlock == 0 && ShadowMap::kBlock % 8 == 0);
  const int size = map.size;
  const float inf = std::numeric_limits<float>::infinity();
  const float* depth = map.depth.data();
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
}

// The nearest of the 5 along rows (or columns) around each block, clamped at the map's edges.
std::vector<float> nearest_of_five(const std::vector<float>& from, int blocks, bool along_rows) {
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
}

// A reach map (see ShadowMap::reach_nearest) from each block's own nearest depth.
std::vector<float> reach_of(const std::vector<float>& nearest, int blocks) {
  return nearest_of_five(nearest_of_five(nearest, blocks, true), blocks, false);
}

// The coarser levels beyond level 1 (made in the bands), and every level's reach map. Each texel
// and block is the nearest of the 2 x 2 under it (an odd last row or column alone).
void build_coarse_levels(ShadowMap& map, std::vector<float> block_nearest) {
  const float* finer = map.depth.data();
  int finer_size = map.size;
  int finer_blocks = map.blocks_per_row;
  for (std::size_t k = 0; k < map.coarse.size() || wants_level(map, finer_size); ++k) {
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
}

// The far lit test's bounds: ShadowMap::visibility's clear_from at each level (distance 16
// texels of level 1 at level 1, and so on) solved for the receiver's depth, the least so far.
void build_clear_below(ShadowMap& map) {
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

// The map's depths from the casters, in bands of rows. An area light's map (soft) also gets its
// coarser levels, reach maps and far lit-test bounds, which only its soft shadows read.
void rasterize_depth(ShadowMap& map, const CasterMesh& casters) {
  const int size = map.size;
  const CasterPlanes planes = project_casters(map, casters);
  const int bands = (size + kBandRows - 1) / kBandRows;
  const CellBins bins =
      bin_items(static_cast<int>(planes.keep.size()), bands, [&](int t, auto&& fn) {
        if (!planes.keep[t]) return;
        const auto& p = planes.projected[t];
        for (int b = p.y0 / kBandRows; b <= p.y1 / kBandRows; ++b) fn(b);
      });
  map.depth = dslr::take_floats(static_cast<size_t>(size) * size);  // every band fills its rows
  const bool soft = map.soft();
  std::vector<float> block_nearest;
  if (soft) {
    map.blocks_per_row = (size + ShadowMap::kBlock - 1) / ShadowMap::kBlock;
    block_nearest.assign(static_cast<size_t>(map.blocks_per_row) * map.blocks_per_row, 0.0f);
  }
  // The first coarser level is made in the bands, while their rows are in cache.
  map.coarse.reserve(kMostCoarseLevels);
  if (soft && wants_level(map, size)) {
    ShadowMap::Level& first = map.coarse.emplace_back();
    first.size = size / 2;  // a whole number of groups of eight texels
    first.depth = dslr::take_floats(static_cast<size_t>(first.size) * first.size);
    first.coverage = dslr::take_floats(static_cast<size_t>(first.size) * first.size);
  }
  tbb::parallel_for(0, bands, [&](int band) {
    const int row0 = band * kBandRows, row1 = std::min(size, row0 + kBandRows);
    rasterize_band_keys(map, planes, bins, band, row0, row1);
    if (!soft) return;
    if (!map.coarse.empty()) {
      // Level 1 for the band's row pairs.
      ShadowMap::Level& first = map.coarse.front();
      const float* depth = map.depth.data();
      for (int y = row0; y < row1; y += 2) {
        const float* top = depth + static_cast<size_t>(y) * size;
        halve_rows(top, top + size, nullptr, nullptr, size,
                   first.depth.data() + static_cast<size_t>(y / 2) * first.size,
                   first.coverage.data() + static_cast<size_t>(y / 2) * first.size);
      }
    }
    band_block_nearest(map, row0, row1, block_nearest);
  });
  if (!soft) return;
  map.reach_nearest = reach_of(block_nearest, map.blocks_per_row);
  for (const float nearest : block_nearest)
    map.nearest_depth = std::min(map.nearest_depth, nearest);
  build_coarse_levels(map, std::move(block_nearest));
  build_clear_below(map);
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

}  // namespace

FrameShadowMaps::FrameShadowMaps(const ir::Scene& scene, const scene::StudioScene& studio,
                                 const Matrix3f& object_rot, const Vector3f& object_t, int size)
    : maps_(scene.studio.lights.size()) {
  const scene::Geometry& object = studio.object;
  const scene::Geometry& room = studio.studio;
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
  tbb::parallel_for(std::size_t{0}, maps_.size(), [&](std::size_t l) {
    maps_[l] =
        build_shadow_map(scene.studio.lights[l], caster_center, caster_radius, casters, size);
  });
}

FrameShadowMaps::~FrameShadowMaps() {
  for (ShadowMap& map : maps_) {
    dslr::recycle(std::move(map.depth));
    for (ShadowMap::Level& level : map.coarse) {
      dslr::recycle(std::move(level.depth));
      dslr::recycle(std::move(level.coverage));
    }
  }
}

}  // namespace rigc::raster
