// Everything the rasterizer draws, prepared once per scene: the object in its own frame (it turns
// with the table), the static studio (turntable, backdrop, floor) in the world frame, and the
// materials with mip-mapped textures in linear colour.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "ir/ir.h"

namespace rigc::scene {

// Linear RGB texture with its mip chain (level 0 is full size).
struct MipTexture {
  struct Level {
    int width = 0;
    int height = 0;
    std::vector<Eigen::Vector3f> texels;
  };
  std::vector<Level> levels;

  // Trilinear lookup; `footprint` is the texel-space size of one pixel at level 0.
  Eigen::Vector3f sample(const Eigen::Vector2f& uv, float footprint) const;
};

struct ShadedMaterial {
  Eigen::Vector3f base_color{0.8f, 0.8f, 0.8f};  // linear
  int texture = -1;                              // index into StudioScene::textures
  float roughness = 0.7f;
  float metallic = 0.0f;
  // The Principled BSDF's specular level: 0.5 is a dielectric's 4 % reflectance at normal
  // incidence (F0 = 0.08 x specular); 0 is a cloth with no sheen, as a backdrop of velvet or
  // muslin is, which reflects neither the lights nor the room.
  float specular = 0.5f;
  ir::SurfacePattern pattern;
  bool casts_shadow = false;  // the object and the turntable; the room only receives
};

// A triangle soup with per-vertex attributes, in one frame.
struct Geometry {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;
  std::vector<Eigen::Vector2f> uvs;  // one per vertex (zeros where the source had none)
  // Linear RGB per vertex in place of the material's base colour (ir::Mesh::colors); empty if
  // none.
  std::vector<Eigen::Vector3f> colors;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<std::int32_t> triangle_material;  // index into StudioScene::materials
  std::vector<Eigen::Vector3f> face_normals;    // unit, from the winding; filled by prepare
  // Per triangle, the convex planar polygon it is a piece of (a quad, a disc's cap; -1: none, or
  // empty for none at all): together they cover that polygon without gaps, so a tile inside it
  // shows its plane alone.
  std::vector<std::int32_t> convex_face;
  std::int32_t convex_faces = 0;

  void compute_face_normals();
};

struct StudioScene {
  Geometry object;  // object frame (object_from_mesh applied)
  Geometry studio;  // world frame
  std::vector<ShadedMaterial> materials;
  std::vector<MipTexture> textures;
  Eigen::Vector3d object_center{0, 0, 0};  // object frame
  double object_radius = 0;                // bounding sphere about object_center
  double turntable_caster_radius = 0;      // bounding sphere of object + turntable, about the axis
  // Triangles that cast shadows, as indices into the object's vertices followed by the studio's
  // (studio vertex i is number object.positions.size() + i).
  std::vector<std::array<std::uint32_t, 3>> shadow_casters;
  // The first `closed_studio_triangles` studio triangles bound solids (turntable, stand): their
  // back faces are hidden by their front faces, so the camera may skip them.
  int closed_studio_triangles = 0;
  // The object's mesh bounds a solid with its faces wound outwards (every directed edge once,
  // its reverse once, positive volume): its back faces can be skipped too.
  bool object_closed = false;
  // Shadow casters from this index on bound closed solids (all of them when the object does).
  std::size_t first_closed_caster = 0;
};

// Whether the triangles bound a solid, consistently wound with the normals outwards.
bool is_closed_outward(const std::vector<Eigen::Vector3f>& positions,
                       const std::vector<std::array<std::uint32_t, 3>>& triangles);

StudioScene prepare_studio_scene(const ir::Scene& scene);

// Albedo multiplier of a procedural pattern at an object-frame position; `footprint_m` is the
// size of a pixel on the surface, so patterns finer than a pixel fade to their mean (no aliasing).
float pattern_factor(const ir::SurfacePattern& pattern, const Eigen::Vector3f& p,
                     float footprint_m);

// Whether `pattern` changes an albedo at all (a kind, and some contrast).
bool has_pattern(const ir::SurfacePattern& pattern);

// pattern_factor at `count` points (object-frame x[i], y[i], z[i]) sharing one footprint,
// written to out[i], eight points per step (pattern_factor is this for one point).
void pattern_factors(const ir::SurfacePattern& pattern, const float* x, const float* y,
                     const float* z, int count, float footprint_m, float* out);
// The same with a footprint per point, footprints_m[i].
void pattern_factors(const ir::SurfacePattern& pattern, const float* x, const float* y,
                     const float* z, int count, const float* footprints_m, float* out);

// Where a pixel sees the surface: the object-frame point under its centre, and the point's change
// across one pixel in x and in y (so the pixel covers at + s dx + t dy, s and t in [-1/2, 1/2]).
struct PixelOnSurface {
  Eigen::Vector3f at, dx, dy;
};
// The pattern's factor averaged over each pixel's area on the surface, a one-pixel box filter as
// the reference renderers apply (their pixel filter): a grid of point samples about a twentieth
// of the pattern's scale apart (at most max_side x max_side), the pattern still fading to its
// mean where a pixel spans more than half its scale. The speckle's samples are taken against
// the few dots that reach the pixel, gathered once (speckle::dots_over8). A pixel whose grid is
// one sample is the pattern at its centre. out[i] for pixels[i], count of them.
inline constexpr int kMaxPatternFilterSide = 8;
void pattern_factors_box(const ir::SurfacePattern& pattern, const PixelOnSurface* pixels, int count,
                         float* out, int max_side = kMaxPatternFilterSide);

}  // namespace rigc::scene
