#include "backends/povray/povray_backend.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <ostream>
#include <regex>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "backends/external/process.h"
#include "backends/external/script_text.h"
#include "dslr/image_io.h"
#include "dslr/lens.h"
#include "io/files.h"
#include "scene/motion_blur.h"
#include "scene/speckle.h"
#include "scene/studio_scene.h"

namespace rigc::povray {

// POV-Ray 3.7's focal blur takes a pupil radius of aperture/4, so aperture = 2·f/N
// (docs/camera-model.md); ReferenceAgreement.DefocusBlurWidth checks it against Cycles, whose
// pupil is f/N by definition.
const double kApertureMetersPerPupilDiameter = 2.0;

namespace {

namespace fs = std::filesystem;
using external::number_text;

constexpr double kPi = std::numbers::pi;
// fade_distance of every local light: POV's 2/(1 + (d/D)²) is 2D²/d² to 1e-6 beyond 1 m·1e-3.
constexpr double kFadeDistance = 1e-3;
constexpr int kMaxSubframes = 16;

std::string vec(const Eigen::Vector3d& v) {
  return fmt::format("<{}, {}, {}>", number_text(v.x()), number_text(v.y()), number_text(v.z()));
}
std::string vec(const Eigen::Vector3f& v) {
  return vec(Eigen::Vector3d(v.cast<double>()));
}

// POV's `matrix` keyword for a column-vector affine transform: its rows are our columns.
std::string pov_matrix(const ir::Mat4& m) {
  return fmt::format("matrix <{}, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}>",
                     number_text(m(0, 0)), number_text(m(1, 0)), number_text(m(2, 0)),
                     number_text(m(0, 1)), number_text(m(1, 1)), number_text(m(2, 1)),
                     number_text(m(0, 2)), number_text(m(1, 2)), number_text(m(2, 2)),
                     number_text(m(0, 3)), number_text(m(1, 3)), number_text(m(2, 3)));
}

std::string material_identifier(int index) {
  return fmt::format("RigcMaterial{}", index);
}
// The macro that makes material `index`'s texture with a vertex's colour.
std::string vertex_texture_macro(int index) {
  return fmt::format("RigcVertexTexture{}", index);
}
std::string texture_file_name(int material) {
  return fmt::format("material_{}.png", material);
}

// The texture times the base colour, in linear light, as a 16-bit PNG read with gamma 1:
// POV-Ray has no way to multiply an image_map by a colour.
bool write_baked_texture(const fs::path& path, const ir::Texture& texture,
                         const Eigen::Vector3f& base_color, std::string* error) {
  const int channels = 3;
  std::vector<std::uint16_t> pixels(static_cast<size_t>(texture.width) * texture.height * 3);
  std::array<float, 256> decode{};
  for (int i = 0; i < 256; ++i) {
    const float c = i / 255.0f;
    decode[i] = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
  }
  for (size_t i = 0; i < static_cast<size_t>(texture.width) * texture.height; ++i) {
    const std::uint8_t* px = &texture.pixels[i * texture.channels];
    for (int c = 0; c < channels; ++c) {
      const float value = decode[px[texture.channels >= 3 ? c : 0]] * base_color[c];
      pixels[i * 3 + c] =
          static_cast<std::uint16_t>(std::lround(std::clamp(value, 0.0f, 1.0f) * 65535));
    }
  }
  OIIO::ImageSpec spec(texture.width, texture.height, channels, OIIO::TypeDesc::UINT16);
  spec.attribute("oiio:ColorSpace", "Linear");
  return dslr::write_pixels(path, spec, pixels.data(), error);
}

// The material's pigment. `base` is its base colour as POV-Ray text: a vector, or the name of a
// macro's colour parameter for vertex colours.
std::string pigment_text(const scene::ShadedMaterial& material, int index, bool is_object,
                         const std::string& base) {
  if (material.texture >= 0) {
    return fmt::format("uv_mapping image_map {{ png {} gamma 1.0 interpolate 2 }}",
                       *external::pov_string_literal(texture_file_name(index)));
  }
  const ir::SurfacePattern& pattern = material.pattern;
  if (!is_object || pattern.kind == ir::PatternKind::kNone || pattern.contrast <= 0) {
    return "rgb " + base;
  }
  const std::string dark = fmt::format("({}) * {}", base, number_text(1 - pattern.contrast));
  const std::string scale = number_text(pattern.scale_m);
  switch (pattern.kind) {
    case ir::PatternKind::kSpeckle:
      // scene/speckle.h's darkness, kept below 1 (a function pattern wraps 1 round to 0).
      return fmt::format(
          "function {{ min(rigc_speckle(x, y, z, {0}), 0.99999) }}\n"
          "      color_map {{ [0 rgb {1}] [1 rgb {2}] }} scale {3}",
          number_text(scene::speckle::seed_offset(pattern.seed)), base, dark, scale);
    case ir::PatternKind::kNoise: {
      // scene/speckle.h's noise, one seed offset per octave.
      std::string seeds;
      for (int k = 0; k < scene::noise::kOctaves; ++k) {
        seeds += ", " + number_text(scene::speckle::seed_offset(pattern.seed + k));
      }
      return fmt::format(
          "function {{ min(rigc_noise(x, y, z{0}), 0.99999) }}\n"
          "      color_map {{ [0 rgb {1}] [1 rgb {2}] }} scale {3}",
          seeds, base, dark, scale);
    }
    case ir::PatternKind::kChecker:
      return fmt::format("checker rgb {}, rgb {} scale {}", base, dark, scale);
    case ir::PatternKind::kNone:
      break;
  }
  return "rgb " + base;
}

// scene/speckle.h's pattern as POV-Ray functions: a function has no local variables, so each
// value used twice is a parameter of the next one.
std::string speckle_functions_text() {
  namespace sp = scene::speckle;
  const std::string p = number_text(sp::kPrime);
  std::string text = fmt::format(
      "#declare rigc_perm = function(pv) {{ mod((34 * pv + 1) * pv, {0}) }}\n"
      "#declare rigc_wrap = function(pv) {{ mod(mod(pv, {0}) + {0}, {0}) }}\n"
      "#declare rigc_smooth = function(pt) {{ pt * pt * (3 - 2 * pt) }}\n"
      "#declare rigc_edge = function(pd, pr, pw) {{\n"
      "  rigc_smooth(min(max((pr + pw - pd) / (2 * pw), 0), 1)) }}\n"
      "#declare rigc_dot_r = function(pd, pr) {{ rigc_edge(pd, pr, min({1}, 0.5 - pr)) }}\n"
      "#declare rigc_dot3 = function(ex, ey, dz, g3) {{\n"
      "  rigc_dot_r(sqrt(ex * ex + ey * ey + pow(dz - g3 / {0}, 2)),\n"
      "             {2} + {3} * rigc_perm(g3 + 1)) }}\n"
      "#declare rigc_dot2 = function(ex, dy, dz, g2) {{\n"
      "  rigc_dot3(ex, dy - g2 / {0}, dz, rigc_perm(g2 + 1)) }}\n"
      "#declare rigc_dot1 = function(dx, dy, dz, g1) {{\n"
      "  rigc_dot2(dx - g1 / {0}, dy, dz, rigc_perm(g1 + 1)) }}\n",
      p, number_text(sp::kEdge), number_text(sp::kRadiusMin),
      number_text(static_cast<double>(sp::kRadiusSpan) / (sp::kPrime - 1)));
  std::string dots;
  for (const float start : sp::kDotStarts) {
    const std::string dot =
        fmt::format("rigc_dot1(dx, dy, dz, rigc_perm(ph + {}))", number_text(start));
    dots = dots.empty() ? dot : fmt::format("max({}, {})", dots, dot);
  }
  text += fmt::format("#declare rigc_cell = function(dx, dy, dz, ph) {{ {} }}\n", dots);
  text +=
      "#declare rigc_hash = function(cx, cy, cz, ps) {\n"
      "  rigc_perm(rigc_perm(rigc_perm(rigc_wrap(cx) + ps) + rigc_wrap(cy)) + rigc_wrap(cz)) }\n"
      "#declare rigc_corner = function(qx, qy, qz, cx, cy, cz, ps) {\n"
      "  rigc_cell(qx - cx, qy - cy, qz - cz, rigc_hash(cx, cy, cz, ps)) }\n";
  std::string corners;
  for (int c = 0; c < 8; ++c) {
    const std::string corner = fmt::format("rigc_corner(qx, qy, qz, bx + {}, by + {}, bz + {}, ps)",
                                           c & 1, (c >> 1) & 1, (c >> 2) & 1);
    corners = corners.empty() ? corner : fmt::format("max({},\n    {})", corners, corner);
  }
  text += fmt::format(
      "#declare rigc_speckle_in = function(qx, qy, qz, bx, by, bz, ps) {{\n  {} }}\n"
      "#declare rigc_speckle = function(qx, qy, qz, ps) {{\n"
      "  rigc_speckle_in(qx, qy, qz, floor(qx - 0.5), floor(qy - 0.5), floor(qz - 0.5), ps) }}\n\n",
      corners);
  return text;
}

// scene/speckle.h's noise as POV-Ray functions (on the speckle's rigc_hash and rigc_smooth).
std::string noise_functions_text() {
  namespace nz = scene::noise;
  std::string text = fmt::format(
      "#declare rigc_lattice = function(cx, cy, cz, ps) {{ rigc_hash(cx, cy, cz, ps) / {} }}\n"
      "#declare rigc_mix = function(pa, pb, pt) {{ pa + (pb - pa) * pt }}\n",
      number_text(scene::speckle::kPrime - 1));
  // value(q, s) from the cell corner f and the smoothed fractions t.
  auto lattice = [](int c) {
    return fmt::format("rigc_lattice(fx + {}, fy + {}, fz + {}, ps)", c & 1, (c >> 1) & 1,
                       (c >> 2) & 1);
  };
  auto along_x = [&](int c) {
    return fmt::format("rigc_mix({}, {}, tx)", lattice(c), lattice(c + 1));
  };
  auto along_y = [&](int c) {
    return fmt::format("rigc_mix({},\n    {}, ty)", along_x(c), along_x(c + 2));
  };
  text += fmt::format(
      "#declare rigc_value_in = function(fx, fy, fz, tx, ty, tz, ps) {{\n"
      "  rigc_mix({},\n  {}, tz) }}\n"
      "#declare rigc_value = function(qx, qy, qz, ps) {{\n"
      "  rigc_value_in(floor(qx), floor(qy), floor(qz), rigc_smooth(qx - floor(qx)),\n"
      "                rigc_smooth(qy - floor(qy)), rigc_smooth(qz - floor(qz)), ps) }}\n",
      along_y(0), along_y(4));
  std::string octaves, seeds;
  for (int k = 0; k < nz::kOctaves; ++k) {
    const std::string f = number_text(nz::kFrequencies[k]);
    octaves += fmt::format("{}{} * rigc_value({} * qx, {} * qy, {} * qz, ps{})",
                           k ? " +\n    " : "", number_text(nz::kAmplitudes[k]), f, f, f, k);
    seeds += fmt::format(", ps{}", k);
  }
  text += fmt::format("#declare rigc_noise = function(qx, qy, qz{}) {{\n  ({}) / {} }}\n\n", seeds,
                      octaves, number_text(nz::kAmplitudeSum));
  return text;
}

// The preview's shading in POV's terms: Lambert (the 1/π is in the light colours) with the whole
// diffuse weight under the highlight, and a Blinn-Phong highlight of the GGX lobe's width
// (exponent 2/α² - 2) and peak. POV adds specular · (n·h)^exponent · light colour, with no n·l;
// the GGX lobe's radiance with light and view along the normal is F0 · D(1) / 4 · E, D(1) =
// 1/(π α²), so specular = F0 / (4 α²).
std::string finish_text(const scene::ShadedMaterial& material) {
  const double metallic = material.metallic;
  const double f0 = 0.08 * material.specular * (1 - metallic) + metallic;
  const double alpha = std::max(static_cast<double>(material.roughness) * material.roughness, 0.05);
  const double exponent = std::max(2 / (alpha * alpha) - 2, 1.0);
  const double specular = f0 / (4 * alpha * alpha);
  if (f0 == 0) {
    return fmt::format("finish {{ ambient {0} diffuse {0} brilliance 1 }}",
                       number_text(1 - metallic));
  }
  return fmt::format("finish {{ ambient {} diffuse {} brilliance 1 specular {} roughness {}{} }}",
                     number_text(1 - metallic), number_text(1 - metallic), number_text(specular),
                     number_text(1 / exponent), metallic > 0.5 ? " metallic" : "");
}

// A material's texture for the mask, the albedo and the lit passes, with its base colour as
// POV-Ray text (see pigment_text).
std::string texture_text(const scene::ShadedMaterial& material, int index, bool is_object,
                         const std::string& base) {
  return fmt::format(
      "#if (RIGC_MASK)\n"
      "  texture {{ pigment {{ rgb {0} }} finish {{ ambient 1 diffuse 0 }} }}\n"
      "#elseif (RIGC_ALBEDO)\n"
      "  texture {{ pigment {{ {1} }} finish {{ ambient 1 diffuse 0 }} }}\n"
      "#else\n  texture {{\n    pigment {{ {1} }}\n    {2}\n  }}\n#end\n",
      is_object ? 1 : 0, pigment_text(material, index, is_object, base), finish_text(material));
}

// Triangle t's material, counted from the mesh's first.
int face_material(const scene::Geometry& g, int t, int material_offset, int material_count) {
  return std::clamp(g.triangle_material[t] - material_offset, 0, std::max(0, material_count - 1));
}

// The texture list of a mesh's materials and its faces, one texture each.
void append_material_faces(fmt::memory_buffer& out, const scene::Geometry& g,
                           const std::vector<int>& triangles, int material_offset,
                           int material_count) {
  fmt::format_to(std::back_inserter(out), " }}\n  texture_list {{ {}", material_count);
  for (int m = 0; m < material_count; ++m) {
    fmt::format_to(std::back_inserter(out), ",\n    texture {{ {} }}",
                   material_identifier(material_offset + m));
  }
  fmt::format_to(std::back_inserter(out), " }}\n  face_indices {{ {}", triangles.size());
  for (int t : triangles) {
    const auto& tri = g.triangles[t];
    fmt::format_to(std::back_inserter(out), ",\n    <{}, {}, {}>, {}", tri[0], tri[1], tri[2],
                   face_material(g, t, material_offset, material_count));
  }
}

// The texture list of a vertex-coloured mesh, a texture per material and vertex colour (each
// made by the material's vertex texture macro), and its faces with a texture per corner, which
// POV-Ray interpolates.
void append_vertex_colored_faces(fmt::memory_buffer& out, const scene::Geometry& g,
                                 const std::vector<int>& triangles, int material_offset,
                                 int material_count) {
  std::map<std::tuple<int, float, float, float>, int> texture_index;
  std::vector<std::array<int, 3>> corners;
  corners.reserve(triangles.size());
  for (int t : triangles) {
    const int material = face_material(g, t, material_offset, material_count);
    std::array<int, 3> corner{};
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f& c = g.colors[g.triangles[t][k]];
      const auto [it, added] = texture_index.try_emplace({material, c.x(), c.y(), c.z()},
                                                         static_cast<int>(texture_index.size()));
      corner[k] = it->second;
    }
    corners.push_back(corner);
  }
  std::vector<std::string> textures(texture_index.size());
  for (const auto& [key, index] : texture_index) {
    const auto& [material, red, green, blue] = key;
    textures[index] =
        fmt::format("{}(<{:.7g}, {:.7g}, {:.7g}>)",
                    vertex_texture_macro(material_offset + material), red, green, blue);
  }
  fmt::format_to(std::back_inserter(out), " }}\n  texture_list {{ {}", textures.size());
  for (const std::string& texture : textures) {
    fmt::format_to(std::back_inserter(out), ",\n    {}", texture);
  }
  fmt::format_to(std::back_inserter(out), " }}\n  face_indices {{ {}", triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const auto& tri = g.triangles[triangles[i]];
    fmt::format_to(std::back_inserter(out), ",\n    <{}, {}, {}>, {}, {}, {}", tri[0], tri[1],
                   tri[2], corners[i][0], corners[i][1], corners[i][2]);
  }
}

void append_mesh2(fmt::memory_buffer& out, const std::string& name, const scene::Geometry& g,
                  const std::vector<int>& triangles, int material_offset, int material_count) {
  fmt::format_to(std::back_inserter(out), "#declare {} = mesh2 {{\n  vertex_vectors {{ {}", name,
                 g.positions.size());
  for (const auto& p : g.positions) {
    fmt::format_to(std::back_inserter(out), ",\n    <{:.7g}, {:.7g}, {:.7g}>", p.x(), p.y(), p.z());
  }
  fmt::format_to(std::back_inserter(out), " }}\n  normal_vectors {{ {}", g.normals.size());
  for (const auto& n : g.normals) {
    fmt::format_to(std::back_inserter(out), ",\n    <{:.6g}, {:.6g}, {:.6g}>", n.x(), n.y(), n.z());
  }
  // RigC's v is 0 at the image top; POV's image_map has v = 0 at the bottom.
  fmt::format_to(std::back_inserter(out), " }}\n  uv_vectors {{ {}", g.uvs.size());
  for (const auto& uv : g.uvs) {
    fmt::format_to(std::back_inserter(out), ",\n    <{:.7g}, {:.7g}>", uv.x(), 1 - uv.y());
  }
  if (g.colors.empty()) {
    append_material_faces(out, g, triangles, material_offset, material_count);
  } else {
    append_vertex_colored_faces(out, g, triangles, material_offset, material_count);
  }
  fmt::format_to(std::back_inserter(out), " }}\n}}\n");
}

std::string light_text(const ir::Light& light) {
  const Eigen::Vector3d color = light.color;
  const double to_colour = 1 / (kPi * 2 * kFadeDistance * kFadeDistance);
  const std::string fade = fmt::format("fade_distance {} fade_power 2", number_text(kFadeDistance));
  switch (light.type) {
    case ir::LightType::kDirectional: {
      const Eigen::Vector3d dir = light.direction.normalized();
      const Eigen::Vector3d center(0, 0, 1);
      return fmt::format("light_source {{ {}, rgb {} parallel point_at {} }}\n",
                         vec(Eigen::Vector3d(center - dir * 50)),
                         vec(Eigen::Vector3d(color * light.illuminance_lx /
                                             external::kCandelaPerBlenderUnit / kPi)),
                         vec(center));
    }
    case ir::LightType::kPoint:
      return fmt::format("light_source {{ {}, rgb {} {} }}\n", vec(light.position),
                         vec(Eigen::Vector3d(color * light.power_w / (4 * kPi) * to_colour)), fade);
    case ir::LightType::kSpot: {
      const double half_deg = light.spot_angle_rad / 2 * 180 / kPi;
      return fmt::format(
          "light_source {{ {}, rgb {} {} spotlight point_at {} radius {} falloff {} tightness 0 "
          "}}\n",
          vec(light.position), vec(Eigen::Vector3d(color * light.power_w / (4 * kPi) * to_colour)),
          fade, vec(Eigen::Vector3d(light.position + light.direction)),
          number_text(half_deg * (1 - light.spot_blend)), number_text(half_deg));
    }
    case ir::LightType::kArea: {
      const Eigen::Vector3d dir = light.direction.normalized();
      Eigen::Vector3d across = Eigen::Vector3d::UnitZ().cross(dir);
      if (across.norm() < 1e-6) across = Eigen::Vector3d::UnitX();
      across.normalize();
      const Eigen::Vector3d along = dir.cross(across).normalized();
      const int cells = 5;
      // POV's grid spans its axes end to end; (cells - 1) / cells of the panel puts its points at
      // the centres of the panel's cells, so that they average the panel uniformly.
      const double span = (cells - 1.0) / cells;
      // A Lambertian panel of power P: intensity P/π·cos θ, one-sided (the spotlight's cos).
      // area_illumination: light and highlights from every cell, not the panel's centre.
      return fmt::format(
          "light_source {{ {}, rgb {} {} spotlight point_at {} radius 90 falloff 90 tightness 1\n"
          "  area_light {}, {}, {}, {} adaptive 1 area_illumination on }}\n",
          vec(light.position), vec(Eigen::Vector3d(color * light.power_w / kPi * to_colour)), fade,
          vec(Eigen::Vector3d(light.position + dir)),
          vec(Eigen::Vector3d(across * (span * std::max(light.size_m.x(), 1e-4)))),
          vec(Eigen::Vector3d(along * (span * std::max(light.size_m.y(), 1e-4)))), cells, cells);
    }
  }
  return "";
}

int antialias_depth(int samples) {
  if (samples <= 0) return 3;
  return std::clamp(static_cast<int>(std::ceil(std::sqrt(static_cast<double>(samples)))), 1, 9);
}

int subframes_for(const ir::Scene& scene, const scene::StudioScene& studio, const ir::Shot& shot,
                  double scale) {
  return std::clamp(scene::motion_blur_subframes(scene, studio, shot, scale), 1, kMaxSubframes);
}

std::string shot_pov(const ir::Scene& scene, const ir::Shot& shot, const dslr::Intrinsics& canvas,
                     int subframes, int samples) {
  const ir::Camera& camera = scene.camera;
  const Eigen::Matrix3d rotation = shot.world_from_camera.block<3, 3>(0, 0);
  const Eigen::Vector3d eye = shot.world_from_camera.block<3, 1>(0, 3);
  const Eigen::Vector3d right = rotation.col(0), down = rotation.col(1), forward = rotation.col(2);
  // Ray = direction + x·right + y·up for x, y in [-1/2, 1/2]: the pinhole of the canvas, with
  // its principal point (pixel centres at +0.5, as POV-Ray traces them).
  const Eigen::Vector3d direction = forward + (canvas.width / 2.0 - canvas.cx) / canvas.fx * right +
                                    (canvas.height / 2.0 - canvas.cy) / canvas.fy * down;
  const double horizontal_fov_deg = 2 * std::atan(canvas.width / (2 * canvas.fx)) * 180 / kPi;
  std::string text = fmt::format(
      "// RigC shot {} of scene '{}'. Render with: povray {}.ini\n"
      "#version 3.7;\n#include \"scene.inc\"\n\n"
      "// Horizontal field of view {:.4f} deg, {} x {} px.\n"
      "camera {{\n  perspective\n  location {}\n  direction {}\n  right {}\n  up {}\n",
      external::comment_text(shot.name), external::comment_text(scene.name),
      external::comment_text(shot.name), horizontal_fov_deg, canvas.width, canvas.height, vec(eye),
      vec(direction), vec(Eigen::Vector3d(right * (canvas.width / canvas.fx))),
      vec(Eigen::Vector3d(-down * (canvas.height / canvas.fy))));
  if (camera.effects.depth_of_field) {
    const double pupil = camera.focal_length_m / camera.aperture_f_number;
    text += fmt::format(
        "  #if (!RIGC_MASK)\n  // f/{:.3g}: pupil diameter {:.3f} mm\n  aperture {}\n"
        "  focal_point {}\n  blur_samples 8, {}\n  confidence 0.9\n  variance 1/256\n"
        "  #end\n",
        camera.aperture_f_number, pupil * 1000,
        number_text(pupil * kApertureMetersPerPupilDiameter),
        vec(Eigen::Vector3d(eye + forward * shot.focus_distance_m)),
        samples > 0 ? std::max(8, samples) : 24);
  }
  text += "}\n\n";
  const double sweep = subframes > 1 ? shot.turntable_velocity_rad_s * camera.shutter_s : 0;
  text += fmt::format(
      "// Motion blur: {} sub-frames spread over the open shutter (the turntable turns {} rad).\n"
      "#declare RigcSubframes = {};\n"
      "#if (RigcSubframes > 1 & !RIGC_MASK)\n"
      "  #declare RigcDelta = {} * ((frame_number - 0.5) / RigcSubframes - 0.5);\n"
      "#else\n  #declare RigcDelta = 0;\n#end\n"
      "object {{ RigcObject\n"
      "  matrix <cos(RigcDelta), sin(RigcDelta), 0, -sin(RigcDelta), cos(RigcDelta), 0, 0, 0, 1, "
      "0, 0, 0>\n  {}\n}}\nobject {{ RigcStudio }}\n",
      subframes, number_text(sweep), subframes, number_text(sweep),
      pov_matrix(ir::world_from_object(scene, shot.turntable_angle_rad)));
  return text;
}

// (Seven parameters: the shot, its canvas and the switches of its INI file.)
std::string shot_ini(const ir::Shot& shot, const dslr::Intrinsics& canvas, int subframes,
                     int samples, bool mask, bool focal_blur, bool albedo) {
  const std::string stem = shot.name;
  std::string text = fmt::format(
      "; RigC: the {} of {}. Run: povray {}{}.ini\n"
      "Input_File_Name={}.pov\n",
      mask ? "object mask" : "image", stem, stem, mask ? "_mask" : "", stem);
  if (albedo && !mask) text += "Declare=RIGC_ALBEDO=1\n";
  if (mask) {
    text += fmt::format("Declare=RIGC_MASK=1\nOutput_File_Name={}_mask.exr\n", stem);
  } else if (subframes > 1) {
    text += fmt::format(
        "Output_File_Name={}_f.exr\nInitial_Frame=1\nFinal_Frame={}\nInitial_Clock=0\n"
        "Final_Clock=1\n",
        stem, subframes);
  } else {
    text += fmt::format("Output_File_Name={}.exr\n", stem);
  }
  text += fmt::format(
      "Output_File_Type=E\nOutput_Alpha=off\nWidth={}\nHeight={}\n"
      "Antialias={}\nSampling_Method=1\nAntialias_Threshold=0.0\nAntialias_Depth={}\n"
      "Jitter=off\nDisplay=off\nPause_When_Done=off\nVerbose=off\n",
      canvas.width, canvas.height,
      // Focal blur already spreads its samples over the pixel; antialiasing on top of it would
      // multiply the rays.
      focal_blur && !mask ? "off" : "on", mask ? 3 : antialias_depth(samples));
  return text;
}

bool write_text_file(const fs::path& path, const std::string& text, std::string* error) {
  return rigc::write_file_atomically(path, text, error);
}

// The shots whose .pov and .ini files the last emit into a folder wrote, one name a line. An
// emit into a folder that held more shots (`compile --target povray` after shots were removed)
// deletes those shots' files, and only those: a `povray` over every .ini there rendered shots
// the scene no longer has.
constexpr const char* kShotListFile = "rigc-shots.txt";

void remove_stale_shot_files(const ir::Scene& scene, const fs::path& dir) {
  std::ifstream listed(dir / kShotListFile);
  std::set<std::string> current;
  for (const auto& shot : scene.shots) current.insert(shot.name);
  std::string name;
  while (std::getline(listed, name)) {
    // Only names an emit could have written: a plain file stem, not a path.
    if (current.count(name) || !external::is_plain_file_stem(name)) continue;
    for (const char* suffix : {".pov", ".ini", "_mask.ini"}) {
      std::error_code ec;
      if (fs::is_regular_file(dir / (name + suffix), ec)) fs::remove(dir / (name + suffix), ec);
    }
  }
}

}  // namespace

bool PovrayBackend::check_settings(const run::RenderSettings& settings, std::string* error) const {
  if (settings.samples != run::kConvergedSamples) return true;
  *error = "POV-Ray has no converged sampling (samples auto) yet: give a count";
  return false;
}

bool PovrayBackend::emit(const ir::Scene& scene, const scene::StudioScene& studio,
                         const fs::path& dir, const run::RenderSettings& settings,
                         std::string* error) {
  const double scale = settings.scale;
  const int samples = settings.samples;
  if (!external::prepare_emit_folder(scene, dir, settings, error)) return false;
  const int object_materials = static_cast<int>(scene.materials.size());
  const int total_materials = static_cast<int>(studio.materials.size());

  fmt::memory_buffer inc;
  auto out = std::back_inserter(inc);
  fmt::format_to(out,
                 "// RigC POV-Ray scene '{}' (from {}; object {}).\n"
                 "// World frame: +Z up, floor at z = 0, metres. Colours are linear; light is in "
                 "Blender's units (1 = 683 cd/m2).\n"
                 "#version 3.7;\n#ifndef (RIGC_MASK)\n  #declare RIGC_MASK = 0;\n#end\n"
                 "#ifndef (RIGC_ALBEDO)\n  #declare RIGC_ALBEDO = 0;\n#end\n\n",
                 external::comment_text(scene.name), external::comment_text(scene.source_file),
                 external::comment_text(scene.object.source));
  const double ambient = scene.studio.ambient_lx / external::kCandelaPerBlenderUnit / kPi;
  fmt::format_to(out,
                 "global_settings {{\n  assumed_gamma 1.0\n  max_trace_level 5\n"
                 "  #if (RIGC_MASK | RIGC_ALBEDO)\n    ambient_light rgb 1\n  #else\n    "
                 "ambient_light rgb {}\n"
                 "  #end\n}}\n\n",
                 number_text(ambient));
  bool procedural = false;
  for (int m = 0; m < object_materials; ++m) {
    const ir::PatternKind kind = studio.materials[m].pattern.kind;
    procedural = procedural || kind == ir::PatternKind::kSpeckle || kind == ir::PatternKind::kNoise;
  }
  if (procedural) fmt::format_to(out, "{}{}", speckle_functions_text(), noise_functions_text());
  for (int m = 0; m < total_materials; ++m) {
    const scene::ShadedMaterial& material = studio.materials[m];
    const bool is_object = m < object_materials;
    if (material.texture >= 0) {
      if (material.texture >= static_cast<int>(scene.textures.size()) ||
          !write_baked_texture(dir / texture_file_name(m), scene.textures[material.texture],
                               material.base_color, error)) {
        if (error->empty()) *error = "a material refers to a missing texture";
        return false;
      }
    }
    // With vertex colours each vertex has the texture with its colour, which POV-Ray
    // interpolates over the triangle (face_indices with three textures).
    if (is_object && !studio.object.colors.empty()) {
      fmt::format_to(out, "#macro {}(RigcColor)\n{}#end\n", vertex_texture_macro(m),
                     texture_text(material, m, is_object, "RigcColor"));
    } else {
      fmt::format_to(out, "#declare {} =\n{}", material_identifier(m),
                     texture_text(material, m, is_object, vec(material.base_color)));
    }
  }
  inc.push_back('\n');
  std::vector<int> object_triangles(studio.object.triangles.size());
  for (size_t t = 0; t < object_triangles.size(); ++t) object_triangles[t] = static_cast<int>(t);
  append_mesh2(inc, "RigcObject", studio.object, object_triangles, 0, object_materials);
  std::vector<int> studio_triangles(studio.studio.triangles.size());
  for (size_t t = 0; t < studio_triangles.size(); ++t) studio_triangles[t] = static_cast<int>(t);
  append_mesh2(inc, "RigcStudio", studio.studio, studio_triangles, object_materials,
               total_materials - object_materials);
  fmt::format_to(out, "\n#if (!RIGC_MASK & !RIGC_ALBEDO)\n");
  for (const auto& light : scene.studio.lights) fmt::format_to(out, "{}", light_text(light));
  fmt::format_to(out, "#end\n");
  if (!write_text_file(dir / "scene.inc", fmt::to_string(inc), error)) return false;

  const dslr::Intrinsics canvas = dslr::render_geometry_for(scene.camera, scale);
  subframes_.assign(scene.shots.size(), 1);
  const bool focal_blur = scene.camera.effects.depth_of_field;
  remove_stale_shot_files(scene, dir);
  for (const auto& shot : scene.shots) {
    const int count = subframes_for(scene, studio, shot, scale);
    subframes_[shot.index] = count;
    if (!write_text_file(dir / (shot.name + ".pov"), shot_pov(scene, shot, canvas, count, samples),
                         error) ||
        !write_text_file(dir / (shot.name + ".ini"),
                         shot_ini(shot, canvas, count, samples, false, focal_blur, albedo_only),
                         error) ||
        !write_text_file(dir / (shot.name + "_mask.ini"),
                         shot_ini(shot, canvas, count, samples, true, focal_blur, albedo_only),
                         error)) {
      return false;
    }
  }
  std::string shot_list;
  for (const auto& shot : scene.shots) shot_list += shot.name + '\n';
  return write_text_file(dir / kShotListFile, shot_list, error);
}

namespace {

bool run_povray(const fs::path& dir, const std::string& ini, const fs::path& log_path,
                std::string* error) {
  const external::ProgramResult result = external::run_program({"povray", ini}, dir, log_path);
  if (!result.started) {
    *error = result.error;
    return false;
  }
  if (result.exit_code != 0) {
    *error = fmt::format("povray {} failed with exit code {}", ini, result.exit_code);
    return false;
  }
  return true;
}

}  // namespace

bool PovrayBackend::render(const ir::Scene& scene, const scene::StudioScene& /*studio*/,
                           const ir::Shot& shot, const run::RenderSettings& settings,
                           const run::ShotFiles& files, run::RenderedShot* out,
                           std::string* error) {
  const fs::path& dir = files.work_dir;
  const fs::path& log_path = files.log;
  const double scale = settings.scale;
  const std::string stem = shot.name;
  const int subframes =
      shot.index < static_cast<int>(subframes_.size()) ? subframes_[shot.index] : 1;
  // Outputs of an earlier run must not pass for this one's.
  const std::regex frame_pattern(stem + "_f[0-9]+\\.exr");
  std::error_code ec;
  std::vector<fs::path> stale = {dir / (stem + ".exr"), dir / (stem + "_mask.exr")};
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (std::regex_match(entry.path().filename().string(), frame_pattern)) {
      stale.push_back(entry.path());
    }
  }
  for (const auto& path : stale) fs::remove(path, ec);

  if (!run_povray(dir, stem + ".ini", log_path, error) ||
      !run_povray(dir, stem + "_mask.ini", log_path, error)) {
    return false;
  }
  std::vector<fs::path> frames;
  if (subframes > 1) {
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
      if (std::regex_match(entry.path().filename().string(), frame_pattern)) {
        frames.push_back(entry.path());
      }
    }
    if (static_cast<int>(frames.size()) != subframes) {
      *error = fmt::format("povray wrote {} of {} sub-frames", frames.size(), subframes);
      return false;
    }
  } else {
    frames.push_back(dir / (stem + ".exr"));
  }
  const dslr::RenderGeometry canvas = dslr::render_geometry_for(scene.camera, scale);
  dslr::LinearFrame& frame = out->frame;
  frame.set_intrinsics(canvas);
  const size_t pixels = static_cast<size_t>(canvas.width) * canvas.height;
  frame.rgb.assign(pixels * 3, 0.0f);
  for (const auto& path : frames) {
    external::LinearImage image;
    if (!external::read_linear_image(path, &image, error)) return false;
    if (image.width != canvas.width || image.height != canvas.height) {
      *error = fmt::format("{} is {} x {}, expected {} x {}", path.filename().string(), image.width,
                           image.height, canvas.width, canvas.height);
      return false;
    }
    const float weight = static_cast<float>(external::kCandelaPerBlenderUnit / frames.size());
    for (size_t i = 0; i < frame.rgb.size(); ++i) frame.rgb[i] += image.rgb[i] * weight;
  }
  external::LinearImage mask;
  if (!external::read_linear_image(dir / (stem + "_mask.exr"), &mask, error)) return false;
  if (mask.width != canvas.width || mask.height != canvas.height) {
    *error = "the mask render has the wrong size";
    return false;
  }
  frame.mask.resize(pixels);
  // Half or more of the pixel's samples on the object, as the preview decides.
  for (size_t i = 0; i < pixels; ++i) frame.mask[i] = mask.rgb[i * 3 + 1] >= 0.5f ? 255 : 0;
  out->depth_of_field_rendered = scene.camera.effects.depth_of_field;
  out->subframes = subframes;
  return true;
}

}  // namespace rigc::povray
