#include "scene/studio_scene.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "dslr/simd.h"
#include "scene/speckle.h"

namespace rigc::scene {
namespace {

using Eigen::Vector2f;
using Eigen::Vector3f;

float srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

MipTexture build_mips(const ir::Texture& texture) {
  MipTexture mips;
  MipTexture::Level base;
  base.width = texture.width;
  base.height = texture.height;
  base.texels.resize(static_cast<size_t>(texture.width) * texture.height);
  // Decode once through a table: sRGB code values to linear.
  std::array<float, 256> decode{};
  for (int i = 0; i < 256; ++i) decode[i] = srgb_to_linear(i / 255.0f);
  const int channels = texture.channels;
  for (size_t i = 0; i < base.texels.size(); ++i) {
    const std::uint8_t* px = &texture.pixels[i * channels];
    if (channels >= 3) {
      base.texels[i] = {decode[px[0]], decode[px[1]], decode[px[2]]};
    } else {
      base.texels[i] = Vector3f::Constant(decode[px[0]]);
    }
  }
  mips.levels.push_back(std::move(base));
  while (mips.levels.back().width > 1 || mips.levels.back().height > 1) {
    const MipTexture::Level& fine = mips.levels.back();
    MipTexture::Level coarse;
    coarse.width = std::max(1, fine.width / 2);
    coarse.height = std::max(1, fine.height / 2);
    coarse.texels.resize(static_cast<size_t>(coarse.width) * coarse.height);
    for (int y = 0; y < coarse.height; ++y) {
      for (int x = 0; x < coarse.width; ++x) {
        Vector3f sum = Vector3f::Zero();
        for (int dy = 0; dy < 2; ++dy) {
          for (int dx = 0; dx < 2; ++dx) {
            int fx = std::min(fine.width - 1, 2 * x + dx);
            int fy = std::min(fine.height - 1, 2 * y + dy);
            sum += fine.texels[static_cast<size_t>(fy) * fine.width + fx];
          }
        }
        coarse.texels[static_cast<size_t>(y) * coarse.width + x] = sum / 4;
      }
    }
    mips.levels.push_back(std::move(coarse));
  }
  return mips;
}

Vector3f bilinear(const MipTexture::Level& level, Vector2f uv) {
  // Repeat wrapping, as glTF's default sampler.
  float u = uv.x() - std::floor(uv.x());
  float v = uv.y() - std::floor(uv.y());
  float x = u * level.width - 0.5f, y = v * level.height - 0.5f;
  int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  float tx = x - x0, ty = y - y0;
  auto at = [&](int xi, int yi) -> const Vector3f& {
    xi = ((xi % level.width) + level.width) % level.width;
    yi = ((yi % level.height) + level.height) % level.height;
    return level.texels[static_cast<size_t>(yi) * level.width + xi];
  };
  return (at(x0, y0) * (1 - tx) + at(x0 + 1, y0) * tx) * (1 - ty) +
         (at(x0, y0 + 1) * (1 - tx) + at(x0 + 1, y0 + 1) * tx) * ty;
}

// The triangles from `first` on are one convex planar face.
void mark_convex_face(Geometry& g, std::size_t first) {
  g.convex_face.resize(first, -1);
  g.convex_face.resize(g.triangles.size(), g.convex_faces++);
}

void add_quad(Geometry& g, const Vector3f& corner, const Vector3f& edge_u, const Vector3f& edge_v,
              int material) {
  const Vector3f normal = edge_u.cross(edge_v).normalized();
  const auto base = static_cast<std::uint32_t>(g.positions.size());
  const Vector3f corners[4] = {corner, corner + edge_u, corner + edge_u + edge_v, corner + edge_v};
  const Vector2f uvs[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int i = 0; i < 4; ++i) {
    g.positions.push_back(corners[i]);
    g.normals.push_back(normal);
    g.uvs.push_back(uvs[i]);
  }
  g.triangles.push_back({base, base + 1, base + 2});
  g.triangles.push_back({base, base + 2, base + 3});
  g.triangle_material.insert(g.triangle_material.end(), 2, material);
  mark_convex_face(g, g.triangles.size() - 2);
}

constexpr int kCylinderSegments = 96;

// Point i of a cylinder's ring of kCylinderSegments at height z.
Vector3f ring_point(float radius, int i, float z) {
  const float a = 2 * std::numbers::pi_v<float> * i / kCylinderSegments;
  return Vector3f(radius * std::cos(a), radius * std::sin(a), z);
}

// A cylinder's smooth side, one flat rectangle (a convex face) per segment.
void add_cylinder_side(Geometry& g, float radius, float z0, float z1, int material) {
  for (int i = 0; i < kCylinderSegments; ++i) {
    const auto base = static_cast<std::uint32_t>(g.positions.size());
    const Vector3f a0 = ring_point(radius, i, z0), a1 = ring_point(radius, i + 1, z0);
    const Vector3f b0 = ring_point(radius, i, z1), b1 = ring_point(radius, i + 1, z1);
    const Vector3f n0(a0.x() / radius, a0.y() / radius, 0), n1(a1.x() / radius, a1.y() / radius, 0);
    for (const auto& [p, n] : {std::pair{a0, n0}, {a1, n1}, {b1, n1}, {b0, n0}}) {
      g.positions.push_back(p);
      g.normals.push_back(n);
      g.uvs.push_back({0, 0});
    }
    g.triangles.push_back({base, base + 1, base + 2});
    g.triangles.push_back({base, base + 2, base + 3});
    g.triangle_material.insert(g.triangle_material.end(), 2, material);
    mark_convex_face(g, g.triangles.size() - 2);  // a flat rectangle
  }
}

// A cylinder's flat cap at height z, facing up (`top`) or down. A zig-zag strip across the disc
// rather than a fan: compact triangles, so their screen boxes do not overlap one another (a fan's
// thin wedges each box half the disc).
void add_cylinder_cap(Geometry& g, float radius, float z, bool top, int material) {
  const auto base = static_cast<std::uint32_t>(g.positions.size());
  const Vector3f normal(0, 0, top ? 1.0f : -1.0f);
  for (int i = 0; i < kCylinderSegments; ++i) {
    g.positions.push_back(ring_point(radius, i, z));
    g.normals.push_back(normal);
    g.uvs.push_back({0, 0});
  }
  // Walk inwards from both ends of the ring: i runs forwards, j backwards.
  auto emit = [&](int a, int b, int c) {
    // Counter-clockwise about the cap's outward normal.
    if (top) {
      g.triangles.push_back({base + a, base + b, base + c});
    } else {
      g.triangles.push_back({base + a, base + c, base + b});
    }
    g.triangle_material.push_back(material);
  };
  const std::size_t first_triangle = g.triangles.size();
  int i = 0, j = kCylinderSegments - 1;
  bool forward = true;
  while (j - i >= 2) {
    if (forward) {
      emit(j, i, i + 1);
      ++i;
    } else {
      emit(j, i, j - 1);
      --j;
    }
    forward = !forward;
  }
  mark_convex_face(g, first_triangle);
}

// A closed cylinder about the Z axis from z0 to z1, smooth sides and flat caps.
void add_cylinder(Geometry& g, float radius, float z0, float z1, int material) {
  add_cylinder_side(g, radius, z0, z1, material);
  for (const float z : {z1, z0}) add_cylinder_cap(g, radius, z, z == z1, material);
}

}  // namespace

Vector3f MipTexture::sample(const Vector2f& uv, float footprint) const {
  if (levels.empty()) return Vector3f::Ones();
  const float lod = std::clamp(std::log2(std::max(footprint, 1e-8f)), 0.0f,
                               static_cast<float>(levels.size() - 1));
  const int fine = static_cast<int>(lod);
  const int coarse = std::min(fine + 1, static_cast<int>(levels.size()) - 1);
  const float t = lod - fine;
  if (t <= 0 || fine == coarse) return bilinear(levels[fine], uv);
  return bilinear(levels[fine], uv) * (1 - t) + bilinear(levels[coarse], uv) * t;
}

float pattern_factor(const ir::SurfacePattern& pattern, const Vector3f& p, float footprint_m) {
  float factor = 1;
  pattern_factors(pattern, &p.x(), &p.y(), &p.z(), 1, footprint_m, &factor);
  return factor;
}

namespace {

// Fade to the mean as the pattern gets finer than about two pixels: 1 keeps it whole.
float pattern_resolve(float scale_m, float footprint_m) {
  return std::clamp(2.0f - 2.0f * footprint_m / scale_m, 0.0f, 1.0f);
}

// The pattern's mean darkness over the surface: what it fades to when too fine to resolve
// (Studio.ResolvedPatternsAverageToTheirFadedValue measures it).
float mean_darkness(const ir::SurfacePattern& pattern) {
  switch (pattern.kind) {
    case ir::PatternKind::kSpeckle:
      return speckle::kMeanDarkness;
    case ir::PatternKind::kNoise:
      return noise::kMeanDarkness;
    case ir::PatternKind::kChecker:
      return 0.5f;
    case ir::PatternKind::kNone:
      break;
  }
  return 0;
}

// The pattern's darkness (clamped to [0, 1] by the caller) at lanes points, in units of its
// scale.
simd::F32x8 pattern_darkness8(const ir::SurfacePattern& pattern, simd::F32x8 qx, simd::F32x8 qy,
                              simd::F32x8 qz, int lanes) {
  using simd::F32x8;
  F32x8 darkness{};
  switch (pattern.kind) {
    case ir::PatternKind::kSpeckle:
      darkness = speckle::darkness8(qx, qy, qz, speckle::seed_offset(pattern.seed),
                                    F32x8{} + speckle::kEdge);
      break;
    case ir::PatternKind::kNoise:
      darkness = noise::darkness8(qx, qy, qz, pattern.seed);
      break;
    case ir::PatternKind::kChecker: {
      for (int k = 0; k < lanes; ++k) {
        darkness[k] = static_cast<float>((static_cast<int>(std::floor(qx[k])) +
                                          static_cast<int>(std::floor(qy[k])) +
                                          static_cast<int>(std::floor(qz[k]))) &
                                         1);
      }
      break;
    }
    case ir::PatternKind::kNone:
      break;
  }
  return darkness;
}

// What the point-sampled and the box-filtered pattern share: its scale, and the factor of a
// darkness (in [0, 1]) seen with a footprint, fading to the pattern's mean as it gets too fine.
struct PatternFade {
  explicit PatternFade(const ir::SurfacePattern& pattern)
      : scale(static_cast<float>(pattern.scale_m)),
        contrast(static_cast<float>(pattern.contrast)),
        mean(mean_darkness(pattern)) {}
  float factor(float darkness, float footprint_m) const {
    const float resolve = pattern_resolve(scale, footprint_m);
    return 1.0f - contrast * (resolve * darkness + (1 - resolve) * mean);
  }
  float scale, contrast, mean;
};

// pattern_factors with point i's footprint footprint_of(i).
// (Seven parameters: points as planes x, y, z with their count, eight a step.)
template <typename FootprintOf>
void pattern_factors_with(const ir::SurfacePattern& pattern, const float* x, const float* y,
                          const float* z, int count, const FootprintOf& footprint_of, float* out) {
  using simd::F32x8;
  if (!has_pattern(pattern)) {
    std::fill_n(out, count, 1.0f);
    return;
  }
  const PatternFade fade(pattern);
  const float scale = fade.scale;
  for (int first = 0; first < count; first += 8) {
    const int lanes = std::min(8, count - first);
    F32x8 qx{}, qy{}, qz{};
    for (int k = 0; k < lanes; ++k) {
      qx[k] = x[first + k] / scale;
      qy[k] = y[first + k] / scale;
      qz[k] = z[first + k] / scale;
    }
    const F32x8 darkness = pattern_darkness8(pattern, qx, qy, qz, lanes);
    for (int k = 0; k < lanes; ++k) {
      out[first + k] = fade.factor(std::clamp(darkness[k], 0.0f, 1.0f), footprint_of(first + k));
    }
  }
}

// Samples of the box filter per pixel side: one per kFilterSpacing of the pattern's scale that
// the side spans, at most max_side.
constexpr float kFilterSpacing = 0.05f;

int filter_side(const Vector3f& side_cells, int max_side) {
  const float n = std::ceil(side_cells.norm() / kFilterSpacing);
  return std::clamp(static_cast<int>(n), 1, max_side);
}

// Point samples of a pattern collected eight at a time; each lane's clamped darkness is added to
// its pixel's sum.
class SampleStream {
 public:
  SampleStream(const ir::SurfacePattern& pattern, float* sums) : pattern_(pattern), sums_(sums) {}
  void add(const Vector3f& q, int pixel) {
    qx_[lanes_] = q.x();
    qy_[lanes_] = q.y();
    qz_[lanes_] = q.z();
    owner_[lanes_] = pixel;
    if (++lanes_ == 8) flush();
  }
  void flush() {
    if (lanes_ == 0) return;
    const simd::F32x8 darkness = pattern_darkness8(pattern_, qx_, qy_, qz_, lanes_);
    for (int k = 0; k < lanes_; ++k) sums_[owner_[k]] += std::clamp(darkness[k], 0.0f, 1.0f);
    lanes_ = 0;
  }

 private:
  const ir::SurfacePattern& pattern_;
  float* sums_;
  simd::F32x8 qx_{}, qy_{}, qz_{};
  std::array<int, 8> owner_{};
  int lanes_ = 0;
};

// A pixel's footprint in cells for the pattern's box filter: its centre and sides, the pixel,
// and its grid of point samples.
struct PixelFootprint {
  Vector3f at, dx, dy;
  int pixel, nx, ny;
};

// The nx x ny grid of point samples over a pixel.
void add_grid(SampleStream& stream, const PixelFootprint& part) {
  for (int j = 0; j < part.ny; ++j) {
    const float t = (j + 0.5f) / part.ny - 0.5f;
    for (int k = 0; k < part.nx; ++k) {
      stream.add(part.at + ((k + 0.5f) / part.nx - 0.5f) * part.dx + t * part.dy, part.pixel);
    }
  }
}

// The sum of the darknesses of a pixel's nx x ny grid of point samples, taken against the only
// dots that reach it, eight samples at a time.
float grid_darkness_sum(const PixelFootprint& pixel, const speckle::CrossingDots& dots) {
  using simd::F32x8;
  const int samples = pixel.nx * pixel.ny;
  const float nx = static_cast<float>(pixel.nx), ny = static_cast<float>(pixel.ny);
  const F32x8 lane = {0, 1, 2, 3, 4, 5, 6, 7};
  F32x8 sum{};
  for (int first = 0; first < samples; first += 8) {
    const F32x8 index = lane + static_cast<float>(first);
    const F32x8 row = simd::floor((index + 0.5f) / nx);
    const F32x8 s = (index - row * nx + 0.5f) / nx - 0.5f, t = (row + 0.5f) / ny - 0.5f;
    const F32x8 qx = pixel.at.x() + s * pixel.dx.x() + t * pixel.dy.x();
    const F32x8 qy = pixel.at.y() + s * pixel.dx.y() + t * pixel.dy.y();
    const F32x8 qz = pixel.at.z() + s * pixel.dx.z() + t * pixel.dy.z();
    const F32x8 darkness = speckle::darkness_of8(qx, qy, qz, dots);  // in [0, 1]
    sum += index < static_cast<float>(samples) ? darkness : F32x8{};
  }
  return simd::sum(sum);
}

// The speckle's box filter, eight pixels at a time: the dots over each pixel are gathered once
// (speckle::dots_over8), then its grid of samples is taken against those dots alone; a pixel
// inside a dot is 1 and one that no dot reaches 0 without a sample.
class SpeckleBoxFilter {
 public:
  SpeckleBoxFilter(const ir::SurfacePattern& pattern, SampleStream& stream, float* sums)
      : seed_offset_(speckle::seed_offset(pattern.seed)), stream_(stream), sums_(sums) {}

  void add(const PixelFootprint& part) {
    parts_[count_++] = part;
    if (count_ == 8) flush();
  }

  void flush() {
    if (count_ == 0) return;
    speckle::Footprints8 footprints{};
    for (int k = 0; k < 8; ++k) {
      const PixelFootprint& part = parts_[std::min(k, count_ - 1)];  // spare lanes: the last
      footprints.qx[k] = part.at.x(), footprints.qy[k] = part.at.y(),
      footprints.qz[k] = part.at.z();
      footprints.dxx[k] = part.dx.x(), footprints.dxy[k] = part.dx.y(),
      footprints.dxz[k] = part.dx.z();
      footprints.dyx[k] = part.dy.x(), footprints.dyy[k] = part.dy.y(),
      footprints.dyz[k] = part.dy.z();
    }
    const unsigned full = speckle::dots_over8(footprints, seed_offset_, crossing_);
    for (int k = 0; k < count_; ++k) {
      const PixelFootprint& part = parts_[k];
      const int samples = part.nx * part.ny;
      if (full >> k & 1u) {
        sums_[part.pixel] += static_cast<float>(samples);
      } else if (crossing_[k].count > 0) {
        sums_[part.pixel] += grid_darkness_sum(part, crossing_[k]);
      } else if (crossing_[k].count < 0) {
        add_grid(stream_, part);
      }
    }
    count_ = 0;
  }

 private:
  float seed_offset_;
  SampleStream& stream_;
  float* sums_;
  std::array<PixelFootprint, 8> parts_;
  std::array<speckle::CrossingDots, 8> crossing_;
  int count_ = 0;
};

}  // namespace

bool has_pattern(const ir::SurfacePattern& pattern) {
  return pattern.kind != ir::PatternKind::kNone && pattern.contrast > 0;
}

void pattern_factors_box(const ir::SurfacePattern& pattern, const PixelOnSurface* pixels, int count,
                         float* out, int max_side) {
  if (!has_pattern(pattern)) {
    std::fill_n(out, count, 1.0f);
    return;
  }
  const PatternFade fade(pattern);
  const float scale = fade.scale;
  // out[i] first sums pixel i's sample darknesses, in units of the pattern's scale.
  std::fill_n(out, count, 0.0f);
  SampleStream stream(pattern, out);
  SpeckleBoxFilter speckle_filter(pattern, stream, out);
  const bool speckle = pattern.kind == ir::PatternKind::kSpeckle;
  for (int i = 0; i < count; ++i) {
    const PixelOnSurface& pixel = pixels[i];
    const float footprint = std::max(pixel.dx.norm(), pixel.dy.norm());
    if (pattern_resolve(scale, footprint) == 0) continue;
    const Vector3f at = pixel.at / scale, dx = pixel.dx / scale, dy = pixel.dy / scale;
    const int nx = filter_side(dx, max_side), ny = filter_side(dy, max_side);
    // A pixel of one sample is the pattern at its centre, whatever the filter.
    if (speckle && nx * ny > 1) {
      speckle_filter.add({at, dx, dy, i, nx, ny});
    } else {
      add_grid(stream, {at, dx, dy, i, nx, ny});
    }
  }
  speckle_filter.flush();
  stream.flush();
  // An unresolved pixel took no samples: its sum of 0 is faded away to the mean entirely.
  for (int i = 0; i < count; ++i) {
    const PixelOnSurface& pixel = pixels[i];
    const int samples =
        filter_side(pixel.dx / scale, max_side) * filter_side(pixel.dy / scale, max_side);
    out[i] = fade.factor(out[i] / samples, std::max(pixel.dx.norm(), pixel.dy.norm()));
  }
}

void pattern_factors(const ir::SurfacePattern& pattern, const float* x, const float* y,
                     const float* z, int count, float footprint_m, float* out) {
  pattern_factors_with(
      pattern, x, y, z, count, [footprint_m](int) { return footprint_m; }, out);
}

void pattern_factors(const ir::SurfacePattern& pattern, const float* x, const float* y,
                     const float* z, int count, const float* footprints_m, float* out) {
  pattern_factors_with(
      pattern, x, y, z, count, [footprints_m](int i) { return footprints_m[i]; }, out);
}

void Geometry::compute_face_normals() {
  face_normals.resize(triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    const Vector3f cross =
        (positions[tri[1]] - positions[tri[0]]).cross(positions[tri[2]] - positions[tri[0]]);
    const float length = cross.norm();
    face_normals[t] = length > 0 ? Vector3f(cross / length) : Vector3f::UnitZ();
  }
}

bool is_closed_outward(const std::vector<Vector3f>& positions,
                       const std::vector<std::array<std::uint32_t, 3>>& triangles) {
  if (triangles.empty()) return false;
  // Vertices at the same position are one corner of the solid (meshes split them for normals
  // and texture seams): number them by position.
  std::vector<std::uint32_t> order(positions.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  auto key = [&](std::uint32_t i) {
    const Vector3f& p = positions[i];
    return std::array<float, 3>{p.x(), p.y(), p.z()};
  };
  tbb::parallel_sort(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
  std::vector<std::uint32_t> corner(positions.size());
  std::uint32_t corners = 0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    if (i > 0 && key(order[i]) != key(order[i - 1])) ++corners;
    corner[order[i]] = corners;
  }
  // Every edge must be shared by exactly two triangles that run along it in opposite directions:
  // sorted by (smaller corner, larger corner, direction), the edges then come in such pairs.
  std::vector<std::uint64_t> edges;
  edges.reserve(3 * triangles.size());
  double volume = 0;
  for (const auto& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t a = corner[t[k]], b = corner[t[(k + 1) % 3]];
      if (a == b) return false;  // a degenerate triangle
      edges.push_back(std::min(a, b) << 33 | std::max(a, b) << 1 | (a > b ? 1 : 0));
    }
    volume += positions[t[0]].cast<double>().dot(
        positions[t[1]].cast<double>().cross(positions[t[2]].cast<double>()));
  }
  if (!(volume > 0)) return false;  // open, inside out, or flat
  tbb::parallel_sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size(); i += 2) {
    if (i + 1 >= edges.size() || (edges[i] ^ edges[i + 1]) != 1) return false;
    if (i + 2 < edges.size() && edges[i + 2] >> 1 == edges[i] >> 1) return false;  // 3 or more
  }
  return true;
}

namespace {

// The scene's materials for shading, then the object moved into its own frame once.
void add_object(const ir::Scene& scene, StudioScene& out) {
  for (const auto& texture : scene.textures) out.textures.push_back(build_mips(texture));
  for (const auto& material : scene.materials) {
    ShadedMaterial shaded;
    shaded.base_color = material.base_color.cast<float>();
    shaded.texture = material.base_color_texture;
    shaded.roughness = static_cast<float>(material.roughness);
    shaded.metallic = static_cast<float>(material.metallic);
    shaded.pattern = material.pattern;
    shaded.casts_shadow = true;
    out.materials.push_back(shaded);
  }
  const ir::Mesh& mesh = scene.object.mesh;
  const Eigen::Matrix4f object_from_mesh = scene.object.object_from_mesh.cast<float>();
  const Eigen::Matrix3f linear = object_from_mesh.block<3, 3>(0, 0);
  const Eigen::Matrix3f normal_matrix = linear.inverse().transpose();
  const Vector3f offset = object_from_mesh.block<3, 1>(0, 3);
  Geometry& object = out.object;
  object.positions.resize(mesh.positions.size());
  object.normals.resize(mesh.positions.size());
  object.uvs.assign(mesh.positions.size(), Vector2f::Zero());
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    object.positions[i] = linear * mesh.positions[i] + offset;
    object.normals[i] = (normal_matrix * mesh.normals[i]).normalized();
    if (!mesh.uvs.empty()) object.uvs[i] = mesh.uvs[i];
  }
  object.colors = mesh.colors;
  object.triangles = mesh.triangles;
  object.triangle_material = mesh.triangle_material;
  if (object.triangle_material.size() != object.triangles.size()) {
    object.triangle_material.assign(object.triangles.size(), 0);
  }
  out.object_center = (scene.object.bounds_min_object + scene.object.bounds_max_object) / 2;
  for (const auto& p : object.positions) {
    out.object_radius = std::max(out.object_radius, (p.cast<double>() - out.object_center).norm());
  }
}

// The studio in the world frame: the turntable on its stand (closed solids, first), the floor
// and the green screen, with their materials.
void add_studio(const ir::Studio& studio, StudioScene& out) {
  auto add_material = [&](const ir::Vec3& color, float roughness, float specular = 0.5f) {
    ShadedMaterial m;
    m.base_color = color.cast<float>();
    m.roughness = roughness;
    m.specular = specular;
    out.materials.push_back(m);
    return static_cast<int>(out.materials.size()) - 1;
  };
  const int table_material = add_material(studio.turntable.color, 0.6f);
  out.materials[table_material].casts_shadow = true;
  // The floor and the backdrop are matte cloth or paper.
  const int floor_material = add_material(studio.floor_color, 0.9f, 0.0f);
  const float top = static_cast<float>(studio.turntable.height_m);
  const float radius = static_cast<float>(studio.turntable.diameter_m / 2);
  add_cylinder(out.studio, radius, top - static_cast<float>(studio.turntable.thickness_m), top,
               table_material);
  // The stand under the disc.
  add_cylinder(out.studio, std::min(0.04f, radius / 2), 0.0f,
               top - static_cast<float>(studio.turntable.thickness_m), table_material);
  out.closed_studio_triangles = static_cast<int>(out.studio.triangles.size());
  add_quad(out.studio, Vector3f(-6, -6, 0), Vector3f(12, 0, 0), Vector3f(0, 12, 0), floor_material);
  if (studio.backdrop.green_screen) {
    const int backdrop_material = add_material(studio.backdrop.color, 0.95f, 0.0f);
    const Vector3f toward = studio.backdrop.direction.cast<float>().normalized();
    const Vector3f across = Vector3f::UnitZ().cross(toward).normalized();
    const float half_width = static_cast<float>(studio.backdrop.width_m / 2);
    const Vector3f center = toward * static_cast<float>(studio.backdrop.distance_m);
    // Wound so that the normal faces the turntable.
    add_quad(out.studio, center + across * half_width, -across * (2 * half_width),
             Vector3f(0, 0, static_cast<float>(studio.backdrop.height_m)), backdrop_material);
  }
}

// The triangles that cast shadows (object first, then studio, indexed into both meshes'
// positions one after the other), and the turntable's reach as a caster.
void collect_shadow_casters(const ir::Studio& studio, StudioScene& out) {
  const auto studio_base = static_cast<std::uint32_t>(out.object.positions.size());
  for (size_t t = 0; t < out.object.triangles.size(); ++t) {
    if (out.materials[out.object.triangle_material[t]].casts_shadow) {
      out.shadow_casters.push_back(out.object.triangles[t]);
    }
  }
  out.first_closed_caster = out.object_closed ? 0 : out.shadow_casters.size();
  for (size_t t = 0; t < out.studio.triangles.size(); ++t) {
    if (!out.materials[out.studio.triangle_material[t]].casts_shadow) continue;
    const auto& tri = out.studio.triangles[t];
    out.shadow_casters.push_back(
        {tri[0] + studio_base, tri[1] + studio_base, tri[2] + studio_base});
  }
  const double table_radius = studio.turntable.diameter_m / 2;
  out.turntable_caster_radius =
      std::max(out.object_center.head<2>().norm() + out.object_radius, table_radius) +
      out.object_center.z() + out.object_radius + studio.turntable.thickness_m;
}

}  // namespace

StudioScene prepare_studio_scene(const ir::Scene& scene) {
  StudioScene out;
  add_object(scene, out);
  add_studio(scene.studio, out);
  out.object.compute_face_normals();
  out.studio.compute_face_normals();
  out.object_closed = is_closed_outward(out.object.positions, out.object.triangles);
  collect_shadow_casters(scene.studio, out);
  return out;
}

}  // namespace rigc::scene
