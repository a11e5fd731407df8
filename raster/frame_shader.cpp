#include "raster/frame_shader.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include "dslr/optics.h"
#include "raster/shadow_visibility.h"
#include "raster/studio_planes.h"
#include "raster/tile_raster.h"

namespace rigc::raster {
namespace {

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

Vector3f unit(const Vector3f& x) {
  return x * (1 / std::sqrt(x.squaredNorm()));
}

// A texture averaged over a pixel's parallelogram uv + s du + t dv (s, t in [-1/2, 1/2]), a
// one-pixel box filter as the reference renderers apply: a grid of up to 4 x 4 (max_side) samples
// about half a texel apart, each from the mip level that their spacing leaves (the finest while
// they are that close).
Vector3f texture_box(const scene::MipTexture& texture, const Vector2f& uv, const Vector2f& du,
                     const Vector2f& dv, int max_side) {
  if (texture.levels.empty()) return Vector3f::Ones();
  const float size =
      static_cast<float>(std::max(texture.levels[0].width, texture.levels[0].height));
  const float texels_u = du.norm() * size, texels_v = dv.norm() * size;
  auto side = [max_side](float texels) {
    return std::clamp(static_cast<int>(std::ceil(2 * texels)), 1, max_side);
  };
  const int nu = side(texels_u), nv = side(texels_v);
  const float spacing = std::max(texels_u / nu, texels_v / nv);
  Vector3f sum = Vector3f::Zero();
  for (int j = 0; j < nv; ++j) {
    const float t = (j + 0.5f) / nv - 0.5f;
    for (int k = 0; k < nu; ++k) {
      sum += texture.sample(uv + ((k + 0.5f) / nu - 0.5f) * du + t * dv, spacing);
    }
  }
  return sum / static_cast<float>(nu * nv);
}

}  // namespace

FrameShader::FrameShader(const ir::Scene& scene, const scene::StudioScene& studio,
                         const FrameRequest& request, const FrameContext& context,
                         const ScreenSetup& setup, const FrameShadowMaps& shadow_maps,
                         dslr::LinearFrame& frame)
    : studio_(studio),
      request_(request),
      setup_(setup),
      screen_tris_(setup.tris),
      shadow_maps_(shadow_maps),
      frame_(frame),
      object_(studio.object),
      room_(studio.studio),
      object_rot_(context.object_rot),
      object_t_(context.object_t),
      cam_rot_(context.cam_rot),
      cam_t_(context.cam_t),
      eye_(context.eye),
      object_tris_(context.object_tris),
      fx_(static_cast<float>(request.canvas.fx)),
      use_blocks_(!request.per_pixel_lighting),
      ambient_lx_(static_cast<float>(scene.studio.ambient_lx)) {
  for (const auto& light : scene.studio.lights)
    lights_.emplace_back(light, light.color.cast<float>());
}

SurfacePoint FrameShader::surface_at(const ScreenTriangle& s, float px, float py,
                                     bool on_plane) const {
  const SourceTriangle source = source_of(s);
  const bool is_object = source.is_object;
  const Vector3f b =
      on_plane ? setup_.source_bary(s, screen_bary(s, px, py)) : source_bary_at(s, px, py);
  const Vector3f p_local = source.at(source.g.positions, b);
  const Vector3f n_local = source.at(source.g.normals, b);
  SurfacePoint sp;
  sp.p = is_object ? Vector3f(object_rot_ * p_local + object_t_) : p_local;
  sp.n = unit(is_object ? Vector3f(object_rot_ * n_local) : n_local);
  sp.v = unit(eye_ - sp.p);
  // Geometric normal for shadow bias; shading normals are flipped towards the viewer, so
  // back faces of open meshes still shade.
  const Vector3f& face_normal = source.g.face_normals[source.local];
  sp.geometric = is_object ? Vector3f(object_rot_ * face_normal) : face_normal;
  if (sp.geometric.dot(sp.v) < 0) sp.geometric = -sp.geometric;
  if (sp.n.dot(sp.v) < 0) sp.n = -sp.n;
  sp.material = source.material();
  return sp;
}

// The viewer's side is taken from the centre's view direction instead of the pixel's own (they
// differ by a pixel's angle), which spares the pixel's surface point; and the cosine is compared
// squared, which spares a square root and a division.
bool FrameShader::normal_agrees(const ScreenTriangle& s, float px, float py,
                                const SurfacePoint& centre) const {
  const SourceTriangle source = source_of(s);
  const Vector3f n_local = source.at(source.g.normals, source_bary_at(s, px, py));
  const Vector3f n = source.is_object ? Vector3f(object_rot_ * n_local) : n_local;
  const float along = n.dot(centre.v) < 0 ? -n.dot(centre.n) : n.dot(centre.n);
  return along > 0 && along * along >= kQuadNormalCos * kQuadNormalCos * n.squaredNorm();
}

AlbedoSample FrameShader::albedo_sample_at(const ScreenTriangle& s, float px, float py) const {
  const SourceTriangle source = source_of(s);
  const bool is_object = source.is_object;
  const scene::ShadedMaterial& material = studio_.materials[source.material()];
  const bool textured =
      material.texture >= 0 && material.texture < static_cast<int>(studio_.textures.size());
  // Vertex colours vary linearly over a triangle: their value at the pixel's centre is their
  // box-filtered mean over the pixel.
  const bool vertex_colored = is_object && !source.g.colors.empty();
  AlbedoSample out;
  out.color = material.base_color;
  out.patterned = is_object && scene::has_pattern(material.pattern);
  if (!textured && !out.patterned && !vertex_colored) return out;
  const Vector3f b = source_bary_at(s, px, py);
  if (vertex_colored) out.color = source.at(source.g.colors, b);
  if (textured) {
    const scene::MipTexture& texture = studio_.textures[material.texture];
    auto uv_at = [&](float qx, float qy) {
      return source.at(source.g.uvs, setup_.source_bary(s, screen_bary(s, qx, qy)));
    };
    const Vector2f uv = source.at(source.g.uvs, b);
    const Vector2f du = uv_at(px + 1, py) - uv_at(px, py);
    const Vector2f dv = uv_at(px, py + 1) - uv_at(px, py);
    out.color = out.color.cwiseProduct(texture_box(texture, uv, du, dv, texture_filter_side()));
  }
  if (out.patterned) {
    // The pixel's extent on the triangle's plane, for the pattern's box filter: a step of one
    // pixel across the view, slid along the view ray onto the plane (first order in the pixel,
    // and free of the screen triangle's shape, which is ill-conditioned for slivers).
    // The plane's point under the pixel's centre, which may lie just outside the triangle
    // (a pixel shaded by its first sample's triangle).
    const Vector3f at =
        source.at(source.g.positions, setup_.source_bary(s, screen_bary(s, px, py)));
    const Vector3f p = object_rot_ * at + object_t_;
    const Vector3f n = object_rot_ * source.g.face_normals[source.local];
    const Vector3f v = unit(eye_ - p);
    const float n_dot_v = n.dot(v);
    const float slant = std::copysign(std::max(std::abs(n_dot_v), 0.2f), n_dot_v);
    const float pixel_m = (cam_rot_ * p + cam_t_).z() / fx_;
    auto step = [&](const Vector3f& across) {
      return Vector3f(object_rot_.transpose() * (pixel_m * (across - v * (n.dot(across) / slant))));
    };
    out.pattern_at = {at, step(cam_rot_.row(0).transpose()), step(cam_rot_.row(1).transpose())};
  }
  return out;
}

Vector3f FrameShader::albedo_at(const ScreenTriangle& s, float px, float py) const {
  AlbedoSample sample = albedo_sample_at(s, px, py);
  if (sample.patterned) {
    const scene::ShadedMaterial& material = studio_.materials[source_of(s).material()];
    float factor = 1;
    scene::pattern_factors_box(material.pattern, &sample.pattern_at, 1, &factor,
                               pattern_filter_side());
    sample.color *= factor;
  }
  return sample.color;
}

void FrameShader::albedo_batch(const int* tris, const int* px, const int* py, int count,
                               Vector3f* out) const {
  std::array<scene::PixelOnSurface, kMaxBatch> pixels;
  std::array<float, kMaxBatch> factor;
  int patterned = 0;
  for (int i = 0; i < count; ++i) {
    const AlbedoSample sample = albedo_sample_at(screen_tris_[tris[i]], px[i] + 0.5f, py[i] + 0.5f);
    out[i] = sample.color;
    patterned += sample.patterned;
    pixels[i] = sample.pattern_at;
  }
  if (patterned == 0) return;
  // One material: either every pixel has the pattern or none does.
  const scene::ShadedMaterial& material =
      studio_.materials[source_of(screen_tris_[tris[0]]).material()];
  scene::pattern_factors_box(material.pattern, pixels.data(), count, factor.data(),
                             pattern_filter_side());
  for (int i = 0; i < count; ++i) out[i] *= factor[i];
}

Lighting FrameShader::lighting_at(const SurfacePoint& sp) const {
  if (request_.albedo_only) return {Vector3f::Ones(), Vector3f::Zero()};
  const scene::ShadedMaterial& material = studio_.materials[sp.material];
  const float metallic = material.metallic;
  // Ambient: a uniform white room of the given illuminance.
  Vector3f diffuse = Vector3f::Constant(ambient_lx_ / kPi);
  Vector3f specular_sum = Vector3f::Zero();
  const float n_dot_v = std::max(sp.n.dot(sp.v), 1e-3f);
  const float f0 = 0.08f * material.specular * (1 - metallic) + metallic;
  for (size_t l = 0; l < lights_.size(); ++l) {
    LightSample sample;
    if (!sample_light(lights_[l], sp.p, &sample)) continue;
    const float n_dot_l = sp.n.dot(sample.to_light);
    const float geo_dot_l = sp.geometric.dot(sample.to_light);
    if (n_dot_l <= 0 || geo_dot_l <= -0.05f) continue;
    const float visibility =
        shadow_maps_[l].visibility(sp.p, sp.geometric, std::max(geo_dot_l, 0.0f));
    if (visibility <= 0) continue;
    const Vector3f h = unit(sample.to_light + sp.v);
    const float specular =
        ggx_specular(n_dot_l, n_dot_v, std::max(sp.n.dot(h), 0.0f), std::max(sp.v.dot(h), 0.0f),
                     material.roughness, f0, sample.half_vector_spread2);
    const Vector3f arriving = sample.illuminance * (n_dot_l * visibility);
    const float burley =
        burley_diffuse(n_dot_l, n_dot_v, sample.to_light.dot(sp.v), material.roughness);
    diffuse += arriving * (burley / kPi);
    if (request_.specular) specular_sum += arriving * specular;
  }
  // brdf = albedo·(1 - metallic)·burley/π + spec_colour·specular, where the specular colour is
  // white for dielectrics and blends towards the albedo with the metallic factor. The diffuse
  // keeps its whole weight under the highlight, as in the Principled BSDF of the Cycles
  // reference (docs/fidelity.md); the ambient room light stays Lambertian.
  return {diffuse * (1 - metallic) + specular_sum * metallic, specular_sum * (1 - metallic)};
}

template <typename KnownAlbedos>
void FrameShader::shade_four(const int* tris, const int* px, const int* py,
                             const KnownAlbedos& known, Vector3f* out) const {
  std::array<Vector3f, 4> scale, offset;
  for (int i = 0; i < 4; ++i) {
    const SurfacePoint sp = surface_at(screen_tris_[tris[i]], px[i] + 0.5f, py[i] + 0.5f);
    const auto lighting = lighting_at(sp);
    scale[i] = lighting.scale;
    offset[i] = lighting.offset;
  }
  std::array<Vector3f, 4> albedo;
  if (!known(px, py, albedo.data())) albedo_batch(tris, px, py, 4, albedo.data());
  for (int i = 0; i < 4; ++i) out[i] = albedo[i].cwiseProduct(scale[i]) + offset[i];
}

bool FrameShader::same_studio_plane(const ScreenTriangle& a, const ScreenTriangle& b) const {
  const SourceTriangle sa = source_of(a), sb = source_of(b);
  return sa.material() == sb.material() &&
         room_.face_normals[sa.local].dot(room_.face_normals[sb.local]) >= kQuadNormalCos;
}

Vector3f FrameShader::shade_on_plane(const ScreenTriangle& s, float px, float py) const {
  const SurfacePoint sp = surface_at(s, px, py, true);
  const Lighting lighting = lighting_at(sp);
  return studio_.materials[sp.material].base_color.cwiseProduct(lighting.scale) + lighting.offset;
}

Vector3f FrameShader::shade(const ScreenTriangle& s, float px, float py) const {
  const SurfacePoint sp = surface_at(s, px, py);
  const Lighting lighting = lighting_at(sp);
  return albedo_at(s, px, py).cwiseProduct(lighting.scale) + lighting.offset;
}

PixelSurfaces FrameShader::single_surface(const float* inv_z, std::int32_t id, int object_samples) {
  PixelSurfaces out;
  out.nearest = std::max({inv_z[0], inv_z[1], inv_z[2], inv_z[3]});
  out.count = 1;
  out.triangle[0] = id;
  out.samples[0] = kSamples;
  out.object_samples = object_samples;
  return out;
}

PixelSurfaces FrameShader::group_samples(const float* inv_z, const std::int32_t* tri) const {
  if (tri[0] >= 0 && tri[0] == tri[1] && tri[0] == tri[2] && tri[0] == tri[3]) {
    // Inside one triangle, as most pixels are.
    return single_surface(inv_z, tri[0], screen_tris_[tri[0]].source < object_tris_ ? kSamples : 0);
  }
  PixelSurfaces out;
  std::array<int, kSamples> surface{-1, -1, -1, -1};
  for (int k = 0; k < kSamples; ++k) {
    const std::int32_t id = tri[k];
    out.nearest = std::max(out.nearest, inv_z[k]);
    if (id < 0 || surface[k] >= 0) continue;
    const bool on_object = screen_tris_[id].source < object_tris_;
    int count = 0;
    for (int j = k; j < kSamples; ++j) {
      const std::int32_t other = tri[j];
      if (other < 0 || surface[j] >= 0) continue;
      if ((screen_tris_[other].source < object_tris_) != on_object) continue;
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
}

void FrameShader::write_pixel(int px, int py, const PixelSurfaces& surfaces,
                              const Vector3f& color) const {
  const size_t pixel = static_cast<size_t>(py) * frame_.width + px;
  frame_.rgb[pixel * 3 + 0] = color.x();
  frame_.rgb[pixel * 3 + 1] = color.y();
  frame_.rgb[pixel * 3 + 2] = color.z();
  frame_.depth_m[pixel] =
      surfaces.nearest > 0 ? 1 / surfaces.nearest : std::numeric_limits<float>::infinity();
  frame_.mask[pixel] = surfaces.object_samples * 2 >= kSamples ? 255 : 0;
}

void FrameShader::shade_pixel(int px, int py, const PixelSurfaces& surfaces) const {
  Vector3f color = Vector3f::Zero();
  for (int i = 0; i < surfaces.count; ++i) {
    color += shade(screen_tris_[surfaces.triangle[i]], px + 0.5f, py + 0.5f) *
             (float(surfaces.samples[i]) / kSamples);
  }
  write_pixel(px, py, surfaces, color);
}

void FrameShader::record_ranges(int x0, int y0, int x1, int y1) const {
  dslr::record_tile_ranges(frame_.rgb.data(), frame_.depth_m.data(), frame_.width, x0, y0, x1, y1,
                           frame_.tile_ranges);
}

namespace {

// The shading of one tile from its samples (see rasterize_tiles), block by block: a 4 x 4 block
// on one plain studio plane is interpolated from its corners (StudioPlanes), one inside a smooth
// patch of the object from its corners' lighting; any other block is shaded in 2 x 2 quads.
class TileShader {
 public:
  TileShader(const FrameShader& shader, const StudioPlanes& planes, int x0, int y0, int x1, int y1,
             const float* inv_z, const std::int32_t* tri)
      : shader_(shader),
        planes_(planes),
        x0_(x0),
        y0_(y0),
        x1_(x1),
        y1_(y1),
        inv_z_(inv_z),
        tri_(tri) {}

  // Shades every pixel of the tile; returns how many quads took a failed block's albedos.
  std::int64_t shade() {
    for (int by = y0_; by < y1_; by += kBlock) {
      for (int bx = x0_; bx < x1_; bx += kBlock) shade_block(bx, by);
    }
    return quads_with_block_albedos_;
  }

 private:
  using Block = std::array<PixelSurfaces, kBlock * kBlock>;

  // The object's corners: lighting (albedo applied per pixel) and shading normal.
  struct ObjectCorner {
    Lighting lighting;
    Vector3f n;
    bool known = false;
  };

  // A bumpy block that failed its light check (shade_object_block) leaves its sixteen albedos
  // here for its quads: the same pixels and triangles, so the same albedos (each a function of
  // its pixel and triangle alone).
  struct BlockAlbedos {
    bool valid = false;
    int bx = 0, by = 0;
    std::array<Vector3f, kBlock * kBlock> albedo;
  };

  // The first of pixel (px, py)'s samples.
  int at(int px, int py) const { return ((py - y0_) * kTileSize + (px - x0_)) * kSamples; }
  const ScreenTriangle& triangle(std::int32_t id) const { return shader_.screen_triangle(id); }
  PixelSurfaces group(int px, int py) const {
    return shader_.group_samples(inv_z_ + at(px, py), tri_ + at(px, py));
  }

  void shade_block(int bx, int by);
  std::int32_t single_triangle(int bx, int by) const;
  bool flat_studio_block(int bx, int by, std::int32_t single_id, Block& block,
                         std::int32_t& plane_triangle) const;
  void write_flat_block(int bx, int by, const Block& block, std::int32_t plane_triangle);

  bool shade_object_block(int bx, int by, std::int32_t single_id);
  int group_object_block(int bx, int by, std::int32_t single_id, Block& block) const;
  std::array<const ObjectCorner*, 4> object_corners(int bx, int by, const Block& block);
  bool light_is_linear(int bx, int by, const Block& block,
                       const std::array<const ObjectCorner*, 4>& corner,
                       const std::array<Vector3f, kBlock * kBlock>& albedo) const;

  void resolve_quad(int qx, int qy);
  bool uniform_quad(int qx, int qy, bool whole, std::array<PixelSurfaces, 4>& quad) const;
  void shade_uniform_quad(int qx, int qy, const std::array<PixelSurfaces, 4>& quad);
  bool known_albedos(const int* px, const int* py, Vector3f* out);

  const FrameShader& shader_;
  const StudioPlanes& planes_;
  const int x0_, y0_, x1_, y1_;
  const float* inv_z_;
  const std::int32_t* tri_;
  BlockAlbedos failed_block_;
  std::int64_t quads_with_block_albedos_ = 0;  // summed once per tile (a shared counter)
  PlaneCorners corners_;
  std::array<ObjectCorner, kCorners * kCorners> object_corner_;
};

void TileShader::shade_block(int bx, int by) {
  const bool whole = shader_.use_blocks() && bx + kBlock <= x1_ && by + kBlock <= y1_;
  Block block;
  std::int32_t plane_triangle = -1;  // the screen triangle that stands for the block's plane
  const std::int32_t single_id = whole ? single_triangle(bx, by) : -1;
  if (whole && flat_studio_block(bx, by, single_id, block, plane_triangle)) {
    write_flat_block(bx, by, block, plane_triangle);
    return;
  }
  if (whole && shade_object_block(bx, by, single_id)) return;
  for (int qy = by; qy < std::min(y1_, by + kBlock); qy += 2) {
    for (int qx = bx; qx < std::min(x1_, bx + kBlock); qx += 2) resolve_quad(qx, qy);
  }
  failed_block_.valid = false;  // its albedos served these quads only
}

// The screen triangle that holds all of the block's samples, or -1 (most blocks lie inside one
// studio triangle).
std::int32_t TileShader::single_triangle(int bx, int by) const {
  const std::int32_t first_id = tri_[at(bx, by)];
  for (int row = 0; row < kBlock; ++row) {
    const std::int32_t* ids = tri_ + at(bx, by + row);
    std::int32_t differ = 0;
    for (int k = 0; k < kBlock * kSamples; ++k) differ |= ids[k] ^ first_id;
    if (differ != 0) return -1;
  }
  return first_id;
}

// Whether the block lies on one plain studio plane, one surface per pixel, without depth steps;
// fills `block` and the triangle that stands for the plane.
bool TileShader::flat_studio_block(int bx, int by, std::int32_t single_id, Block& block,
                                   std::int32_t& plane_triangle) const {
  if (single_id >= 0 && shader_.plain_studio(triangle(single_id))) {
    for (int i = 0; i < kBlock * kBlock; ++i) {
      block[i] =
          FrameShader::single_surface(inv_z_ + at(bx + i % kBlock, by + i / kBlock), single_id, 0);
    }
    plane_triangle = single_id;
    return true;
  }
  for (int i = 0; i < kBlock * kBlock; ++i) {
    block[i] = group(bx + i % kBlock, by + i / kBlock);
    const PixelSurfaces& b = block[i];
    if (b.count != 1 || b.samples[0] != kSamples) return false;
    const ScreenTriangle& t = triangle(b.triangle[0]);
    if (i == 0) {
      plane_triangle = b.triangle[0];
      if (!shader_.plain_studio(t)) return false;
      continue;
    }
    if (!(shader_.plain_studio(t) && shader_.same_studio_plane(t, triangle(plane_triangle)) &&
          std::abs(b.nearest - block[0].nearest) <= 0.02f * block[0].nearest)) {
      return false;
    }
  }
  return true;
}

// Radiance at the block's corners, on the plane (unclamped barycentrics reach past the
// triangle's edges along the plane), blended over its pixels.
void TileShader::write_flat_block(int bx, int by, const Block& block, std::int32_t plane_triangle) {
  const ScreenTriangle& plane = triangle(plane_triangle);
  std::array<Vector3f, 4> corner;
  for (int k = 0; k < 4; ++k) {
    corner[k] = planes_.corner(corners_, plane, x0_, y0_, (bx - x0_) / kBlock + (k & 1),
                               (by - y0_) / kBlock + (k >> 1));
  }
  for (int i = 0; i < kBlock * kBlock; ++i) {
    const int px = bx + i % kBlock, py = by + i / kBlock;
    const float fx = (i % kBlock + 0.5f) / kBlock, fy = (i / kBlock + 0.5f) / kBlock;
    const Vector3f color = (1 - fy) * ((1 - fx) * corner[0] + fx * corner[1]) +
                           fy * ((1 - fx) * corner[2] + fx * corner[3]);
    shader_.write_pixel(px, py, block[i], color);
  }
}

// A 4 x 4 block inside one smooth patch of the object: the lights are summed at the block's
// corners (shared with the neighbouring blocks) and interpolated, the albedo taken per pixel; the
// block must be one material, one surface per pixel, without depth steps, and its corner normals
// within kBlockNormalCos of each other (or within kBlockBumpyNormalCos and its light nearly
// linear). False (and nothing written) otherwise. `single_id`: the screen triangle that holds all
// of the block's samples, if one does (-1 otherwise); its pixels then need no grouping and its
// material no lookup per pixel.
bool TileShader::shade_object_block(int bx, int by, std::int32_t single_id) {
  failed_block_.valid = false;
  Block block;
  const int material = group_object_block(bx, by, single_id, block);
  if (material < 0) return false;
  const std::array<const ObjectCorner*, 4> corner = object_corners(bx, by, block);
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
  shader_.albedo_batch(tris.data(), pxs.data(), pys.data(), kBlock * kBlock, albedo.data());
  if (!smooth && !light_is_linear(bx, by, block, corner, albedo)) {
    failed_block_.valid = true;
    failed_block_.bx = bx;
    failed_block_.by = by;
    failed_block_.albedo = albedo;
    return false;
  }
  for (int i = 0; i < kBlock * kBlock; ++i) {
    const float fx = (i % kBlock + 0.5f) / kBlock, fy = (i / kBlock + 0.5f) / kBlock;
    const float w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    Vector3f scale = Vector3f::Zero(), offset = Vector3f::Zero();
    for (int k = 0; k < 4; ++k) {
      scale += w[k] * corner[k]->lighting.scale;
      offset += w[k] * corner[k]->lighting.offset;
    }
    shader_.write_pixel(pxs[i], pys[i], block[i], albedo[i].cwiseProduct(scale) + offset);
  }
  return true;
}

// The block's pixels, each one surface of the object wholly, of one material and without depth
// steps: that material, or -1.
int TileShader::group_object_block(int bx, int by, std::int32_t single_id, Block& block) const {
  int material = -1;
  if (single_id >= 0) {
    if (!shader_.on_object(triangle(single_id))) return -1;
    material = shader_.source_of(triangle(single_id)).material();
  }
  for (int i = 0; i < kBlock * kBlock; ++i) {
    const int px = bx + i % kBlock, py = by + i / kBlock;
    if (single_id >= 0) {
      block[i] = FrameShader::single_surface(inv_z_ + at(px, py), single_id, kSamples);
    } else {
      block[i] = group(px, py);
    }
    const PixelSurfaces& b = block[i];
    if (single_id < 0) {
      if (b.count != 1 || b.samples[0] != kSamples || b.object_samples != kSamples) return -1;
      const int m = shader_.source_of(triangle(b.triangle[0])).material();
      if (i == 0) material = m;
      if (m != material) return -1;
    }
    if (std::abs(b.nearest - block[0].nearest) > 0.01f * block[0].nearest) return -1;
  }
  return material;
}

// The block's four corners' lighting, each worked out once per tile.
std::array<const TileShader::ObjectCorner*, 4> TileShader::object_corners(int bx, int by,
                                                                          const Block& block) {
  std::array<const ObjectCorner*, 4> corner;
  for (int k = 0; k < 4; ++k) {
    const int cx = (bx - x0_) / kBlock + (k & 1), cy = (by - y0_) / kBlock + (k >> 1);
    ObjectCorner& c = object_corner_[cy * kCorners + cx];
    if (!c.known) {
      // On the plane of the triangle under the block's pixel at this corner.
      const int pixel = (k >> 1) * (kBlock - 1) * kBlock + (k & 1) * (kBlock - 1);
      const SurfacePoint sp = shader_.surface_at(triangle(block[pixel].triangle[0]),
                                                 static_cast<float>(bx + kBlock * (k & 1)),
                                                 static_cast<float>(by + kBlock * (k >> 1)), true);
      c.lighting = shader_.lighting_at(sp);
      c.n = sp.n;
      c.known = true;
    }
    corner[k] = &c;
  }
  return corner;
}

// Corner normals apart (kBlockBumpyNormalCos): the lights summed at the block's centre against
// the corners' mean, for the block's mean albedo. Where the light bends inside the block (a
// penumbra, a highlight, a crease), the bilinear fill would miss it, and the block is shaded in
// quads.
bool TileShader::light_is_linear(int bx, int by, const Block& block,
                                 const std::array<const ObjectCorner*, 4>& corner,
                                 const std::array<Vector3f, kBlock * kBlock>& albedo) const {
  const int centre_pixel = (kBlock / 2) * kBlock + kBlock / 2;
  const SurfacePoint sp = shader_.surface_at(triangle(block[centre_pixel].triangle[0]),
                                             static_cast<float>(bx + kBlock / 2),
                                             static_cast<float>(by + kBlock / 2), true);
  const Lighting exact = shader_.lighting_at(sp);
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
  return !((have - want).cwiseAbs().array() > kBlockLightTolerance * want.array()).any();
}

// 2 x 2 quads inside one surface sum the lights once, at the quad's centre, and take the albedo
// (texture, pattern) per pixel: lighting varies slowly across two pixels, the surface's detail
// does not. Quads that hold an edge, and odd last rows and columns, are shaded pixel by pixel.
void TileShader::resolve_quad(int qx, int qy) {
  const bool whole = qx + 1 < x1_ && qy + 1 < y1_ && !shader_.request().per_pixel_lighting;
  std::array<PixelSurfaces, 4> quad;
  if (uniform_quad(qx, qy, whole, quad)) {
    shade_uniform_quad(qx, qy, quad);
    return;
  }
  for (int i = 0; i < 4; ++i) {
    const int px = qx + (i & 1), py = qy + (i >> 1);
    if (px >= x1_ || py >= y1_) continue;
    if (!whole) quad[i] = group(px, py);
    shader_.shade_pixel(px, py, quad[i]);
  }
}

// Whether the quad is whole and its four pixels each one surface of the same kind (object or
// studio) and material without a depth step. Groups the pixels' samples into `quad` (only the
// first pixel's when the quad is not whole).
bool TileShader::uniform_quad(int qx, int qy, bool whole,
                              std::array<PixelSurfaces, 4>& quad) const {
  bool uniform = whole;
  for (int i = 0; i < 4 && (whole || i == 0); ++i) {
    const int px = qx + (i & 1), py = qy + (i >> 1);
    if (px >= x1_ || py >= y1_) continue;
    quad[i] = group(px, py);
    uniform = uniform && quad[i].count == 1 && quad[i].samples[0] == kSamples;
  }
  if (uniform) {
    const ScreenTriangle& first = triangle(quad[0].triangle[0]);
    const bool on_object = shader_.on_object(first);
    for (int i = 1; i < 4 && uniform; ++i) {
      const ScreenTriangle& other = triangle(quad[i].triangle[0]);
      uniform = shader_.on_object(other) == on_object &&
                shader_.source_of(other).material() == shader_.source_of(first).material() &&
                std::abs(quad[i].nearest - quad[0].nearest) <= 0.01f * quad[0].nearest;
    }
  }
  return uniform;
}

void TileShader::shade_uniform_quad(int qx, int qy, const std::array<PixelSurfaces, 4>& quad) {
  const ScreenTriangle& first = triangle(quad[0].triangle[0]);
  SurfacePoint centre = shader_.surface_at(first, qx + 1.0f, qy + 1.0f);
  const scene::ShadedMaterial& material = shader_.material(centre.material);
  bool flat = shader_.plain_studio(first);
  for (int i = 1; i < 4 && flat; ++i) {
    flat = shader_.same_studio_plane(triangle(quad[i].triangle[0]), first);
  }
  if (flat) {
    // Studio surfaces are plain planes: one colour for a quad within one of them.
    const Lighting lighting = shader_.lighting_at(centre);
    const Vector3f color = material.base_color.cwiseProduct(lighting.scale) + lighting.offset;
    for (int i = 0; i < 4; ++i) shader_.write_pixel(qx + (i & 1), qy + (i >> 1), quad[i], color);
    return;
  }
  // Otherwise the lights are summed once, at the quad's centre, when the four pixels' shading
  // normals agree with its normal (a smooth patch), else per pixel.
  bool smooth = true;
  for (int i = 0; i < 4 && smooth; ++i) {
    smooth = shader_.normal_agrees(triangle(quad[i].triangle[0]), qx + (i & 1) + 0.5f,
                                   qy + (i >> 1) + 0.5f, centre);
  }
  std::array<int, 4> tris, pxs, pys;
  for (int i = 0; i < 4; ++i) {
    tris[i] = quad[i].triangle[0];
    pxs[i] = qx + (i & 1);
    pys[i] = qy + (i >> 1);
  }
  if (smooth) {
    const Lighting lighting = shader_.lighting_at(centre);
    std::array<Vector3f, 4> albedo;
    if (!known_albedos(pxs.data(), pys.data(), albedo.data())) {
      shader_.albedo_batch(tris.data(), pxs.data(), pys.data(), 4, albedo.data());
    }
    for (int i = 0; i < 4; ++i) {
      shader_.write_pixel(pxs[i], pys[i], quad[i],
                          albedo[i].cwiseProduct(lighting.scale) + lighting.offset);
    }
    return;
  }
  // A bumpy patch: each pixel lit on its own; the albedos (the pattern) in one batch.
  std::array<Vector3f, 4> colors;
  auto known = [this](const int* px, const int* py, Vector3f* out) {
    return known_albedos(px, py, out);
  };
  shader_.shade_four(tris.data(), pxs.data(), pys.data(), known, colors.data());
  for (int i = 0; i < 4; ++i) shader_.write_pixel(pxs[i], pys[i], quad[i], colors[i]);
}

// The failed block's albedos for four of its pixels, when they serve (see BlockAlbedos).
bool TileShader::known_albedos(const int* px, const int* py, Vector3f* out) {
  if (!failed_block_.valid || !shader_.request().reuse_block_albedos) return false;
  for (int i = 0; i < 4; ++i) {
    out[i] = failed_block_.albedo[(py[i] - failed_block_.by) * kBlock + px[i] - failed_block_.bx];
  }
  ++quads_with_block_albedos_;
  return true;
}

}  // namespace

std::int64_t FrameShader::shade_tiles(std::uint64_t frame_serial) const {
  const StudioPlanes planes(*this, frame_serial);
  std::atomic<std::int64_t> quads_with_block_albedos{0};
  // The studio's convex planar faces (quads, the discs' caps), for the tiles they cover together.
  auto face_of = [&](const ScreenTriangle& t) -> std::int32_t {
    if (t.source < object_tris_) return -1;
    const auto local = static_cast<std::size_t>(t.source - object_tris_);
    return local < room_.convex_face.size() ? room_.convex_face[local] : -1;
  };
  auto plain_studio_tile = [&](int x0, int y0, int x1, int y1, std::int32_t id) {
    if (!planes.fill_tile(x0, y0, x1, y1, id)) return false;
    record_ranges(x0, y0, x1, y1);
    return true;
  };
  rasterize_tiles<kSamples>(
      setup_, request_.canvas, face_of, plain_studio_tile,
      [&](int x0, int y0, int x1, int y1, const float* inv_z, const std::int32_t* tri) {
        TileShader tile(*this, planes, x0, y0, x1, y1, inv_z, tri);
        const std::int64_t quads = tile.shade();
        if (quads > 0) quads_with_block_albedos.fetch_add(quads, std::memory_order_relaxed);
        record_ranges(x0, y0, x1, y1);
      });
  return quads_with_block_albedos.load();
}

}  // namespace rigc::raster
