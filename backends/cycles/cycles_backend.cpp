#include "backends/cycles/cycles_backend.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <array>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <numbers>
#include <ostream>
#include <string>
#include <vector>

#include "backends/external/process.h"
#include "backends/external/script_text.h"
#include "dslr/exposure.h"
#include "dslr/image_io.h"
#include "dslr/lens.h"
#include "dslr/sensor.h"
#include "io/files.h"
#include "scene/speckle.h"
#include "scene/studio_scene.h"

namespace rigc::cycles {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr double kPi = std::numbers::pi;

constexpr const char* kScriptTemplate =
#include "backends/cycles/cycles_script.py.inc"
    ;

json matrix_rows(const ir::Mat4& m) {
  json rows = json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

json vec3(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

// Blender lights shine along their local -Z.
ir::Mat4 light_matrix(const ir::Light& light) {
  const Eigen::Vector3d dir = light.direction.normalized();
  Eigen::Vector3d across = Eigen::Vector3d::UnitZ().cross(dir);
  if (across.norm() < 1e-6) across = Eigen::Vector3d::UnitX();
  across.normalize();
  const Eigen::Vector3d z = -dir;
  const Eigen::Vector3d y = z.cross(across);
  ir::Mat4 m = ir::Mat4::Identity();
  m.block<3, 1>(0, 0) = across;
  m.block<3, 1>(0, 1) = y;
  m.block<3, 1>(0, 2) = z;
  m.block<3, 1>(0, 3) = light.position;
  return m;
}

json light_json(const ir::Light& light, int index) {
  json spec = {{"name", fmt::format("RigcLight{}", index)},
               {"color", vec3(light.color)},
               {"matrix", matrix_rows(light_matrix(light))}};
  switch (light.type) {
    case ir::LightType::kPoint:
      spec["type"] = "POINT";
      spec["energy"] = light.power_w;
      break;
    case ir::LightType::kSpot:
      spec["type"] = "SPOT";
      spec["energy"] = light.power_w;
      spec["spot_size"] = std::clamp(light.spot_angle_rad, 1e-3, kPi);
      spec["spot_blend"] = std::clamp(light.spot_blend, 0.0, 1.0);
      break;
    case ir::LightType::kArea:
      spec["type"] = "AREA";
      spec["energy"] = light.power_w;
      spec["size"] = {std::max(light.size_m.x(), 1e-4), std::max(light.size_m.y(), 1e-4)};
      break;
    case ir::LightType::kDirectional:
      spec["type"] = "SUN";
      spec["energy"] = light.illuminance_lx / external::kCandelaPerBlenderUnit;
      break;
  }
  return spec;
}

std::string texture_file_name(int texture) {
  return fmt::format("texture_{}.png", texture);
}

// The texture's colour in linear light, as a 16-bit RGB PNG the script reads as Non-Color data.
// Cycles keeps an 8-bit sRGB image in its code values and decodes after interpolating, so its
// bilinear blend between texels would be a blend of sRGB codes: darker than the blend of light
// that the preview and POV-Ray compute (docs/surface-functions.md). Alpha is dropped, as the
// preview ignores it.
bool write_linear_texture(const fs::path& path, const ir::Texture& texture, std::string* error) {
  std::array<std::uint16_t, 256> decode{};
  for (int i = 0; i < 256; ++i) {
    const double c = i / 255.0;
    const double linear = c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
    decode[i] = static_cast<std::uint16_t>(std::lround(linear * 65535));
  }
  const size_t texels = static_cast<size_t>(texture.width) * texture.height;
  std::vector<std::uint16_t> pixels(texels * 3);
  for (size_t i = 0; i < texels; ++i) {
    const std::uint8_t* px = &texture.pixels[i * texture.channels];
    for (int c = 0; c < 3; ++c) pixels[i * 3 + c] = decode[px[texture.channels >= 3 ? c : 0]];
  }
  OIIO::ImageSpec spec(texture.width, texture.height, 3, OIIO::TypeDesc::UINT16);
  spec.attribute("oiio:ColorSpace", "Linear");
  return dslr::write_pixels(path, spec, pixels.data(), error);
}

// `vertex_colors`: the mesh's vertex colours are the base colour.
json material_json(const ir::Scene& scene, const scene::ShadedMaterial& material, int index,
                   bool is_object, bool vertex_colors) {
  std::string name = index < static_cast<int>(scene.materials.size())
                         ? scene.materials[index].name
                         : fmt::format("rigc_studio_{}", index);
  json spec = {{"name", name},
               {"base_color", vec3(material.base_color.cast<double>())},
               {"roughness", material.roughness},
               {"metallic", material.metallic},
               {"specular", material.specular},
               {"texture",
                material.texture >= 0 ? json(texture_file_name(material.texture)) : json(nullptr)},
               {"pattern", nullptr},
               {"vertex_colors", vertex_colors}};
  const ir::SurfacePattern& pattern = material.pattern;
  if (is_object && pattern.kind != ir::PatternKind::kNone && pattern.contrast > 0) {
    const char* kind = pattern.kind == ir::PatternKind::kChecker   ? "checker"
                       : pattern.kind == ir::PatternKind::kSpeckle ? "speckle"
                                                                   : "noise";
    spec["pattern"] = {{"kind", kind},
                       {"scale", pattern.scale_m},
                       {"contrast", pattern.contrast},
                       {"seed", scene::speckle::seed_offset(pattern.seed)}};
    if (pattern.kind == ir::PatternKind::kNoise) {
      json seeds = json::array();
      for (int k = 0; k < scene::noise::kOctaves; ++k) {
        seeds.push_back(scene::speckle::seed_offset(pattern.seed + k));
      }
      spec["pattern"]["octave_seeds"] = seeds;
    }
  }
  return spec;
}

// Appends the mesh the way Blender's foreach_set wants it: per-vertex positions, normals and
// RGBA colours (if any), per-loop vertex indices and UVs (v flipped: Blender's v = 0 is the image
// bottom).
json append_geometry(std::string& bytes, const scene::Geometry& g, int material_offset,
                     int material_count) {
  auto append = [&](const void* data, size_t size) {
    const size_t offset = bytes.size();
    bytes.append(static_cast<const char*>(data), size);
    return offset;
  };
  json spec;
  spec["vertex_count"] = g.positions.size();
  spec["triangle_count"] = g.triangles.size();
  std::vector<float> floats;
  for (const auto& p : g.positions) floats.insert(floats.end(), {p.x(), p.y(), p.z()});
  spec["positions"] = append(floats.data(), floats.size() * sizeof(float));
  floats.clear();
  for (const auto& n : g.normals) floats.insert(floats.end(), {n.x(), n.y(), n.z()});
  spec["normals"] = append(floats.data(), floats.size() * sizeof(float));
  std::vector<std::int32_t> ints;
  floats.clear();
  for (const auto& tri : g.triangles) {
    for (const std::uint32_t v : tri) {
      ints.push_back(static_cast<std::int32_t>(v));
      floats.push_back(g.uvs[v].x());
      floats.push_back(1 - g.uvs[v].y());
    }
  }
  spec["loop_vertices"] = append(ints.data(), ints.size() * sizeof(std::int32_t));
  spec["loop_uvs"] = append(floats.data(), floats.size() * sizeof(float));
  ints.clear();
  for (const std::int32_t m : g.triangle_material) {
    ints.push_back(std::clamp(m, material_offset, material_offset + material_count - 1));
  }
  spec["materials"] = append(ints.data(), ints.size() * sizeof(std::int32_t));
  if (!g.colors.empty()) {
    floats.clear();
    for (const auto& c : g.colors) floats.insert(floats.end(), {c.x(), c.y(), c.z(), 1.0f});
    spec["vertex_colors"] = append(floats.data(), floats.size() * sizeof(float));
  }
  return spec;
}

std::string script_text(const json& data) {
  const std::string literal =
      external::python_string_literal(data.dump(-1, ' ', true, json::error_handler_t::replace));
  std::string script = kScriptTemplate;
  const std::string placeholder = "@DATA@";
  script.replace(script.find(placeholder), placeholder.size(), literal);
  const std::string header = fmt::format(
      "# RigC: Blender Cycles scene '{}' (object {}).\n"
      "# Run: blender -b --factory-startup --python scene.py [-- --shot N[,N...] --samples N "
      "--seed N --out DIR]\n",
      external::comment_text(data["scene"].get<std::string>()),
      external::comment_text(data["object_source"].get<std::string>()));
  return header + script;
}

}  // namespace

double converged_noise_threshold(const ir::Camera& camera) {
  // The measured form of 0.69/sqrt(g) (docs/fidelity.md, "Converged references").
  constexpr double kThresholdTimesRootElectrons = 0.45;
  const double electrons_per_unit = dslr::exposure_scale(camera) *
                                    dslr::electrons_at_clipping(camera.noise, camera.iso) *
                                    external::kCandelaPerBlenderUnit;
  return kThresholdTimesRootElectrons / std::sqrt(electrons_per_unit);
}

int cycles_seed(std::uint64_t run_seed, int shot_index) {
  constexpr std::uint64_t kSeedsPerRun = 1000003;  // a prime above any run's shot count
  return static_cast<int>(((run_seed - 1) * kSeedsPerRun + static_cast<std::uint64_t>(shot_index)) %
                          (1ull << 31));
}

std::string CyclesBackend::options_key() const {
  std::vector<std::string> changed;
  if (albedo_only) changed.push_back("albedo_only");
  if (max_bounces != kDefaultMaxBounces)
    changed.push_back(fmt::format("max_bounces={}", max_bounces));
  return fmt::format("{}", fmt::join(changed, ";"));
}

bool CyclesBackend::emit(const ir::Scene& scene, const scene::StudioScene& studio,
                         const fs::path& dir, const run::RenderSettings& settings,
                         std::string* error) {
  const double scale = settings.scale;
  const int samples = settings.samples;
  if (!external::prepare_emit_folder(scene, dir, settings, error)) return false;
  const int object_materials = static_cast<int>(scene.materials.size());
  const int total_materials = static_cast<int>(studio.materials.size());
  const ir::Camera& camera = scene.camera;
  const dslr::RenderGeometry canvas = dslr::render_geometry_for(camera, scale);

  json data;
  data["scene"] = scene.name;
  data["object_source"] = scene.object.source;
  data["source_file"] = scene.source_file;
  data["width"] = canvas.width;
  data["height"] = canvas.height;
  const bool converged = samples == run::kConvergedSamples;
  data["samples"] = converged     ? CyclesBackend::kConvergedMaxSamples
                    : samples > 0 ? samples
                                  : CyclesBackend::kDefaultSamples;
  data["noise_threshold"] = converged ? converged_noise_threshold(camera) : 0.0;
  data["shutter_s"] = camera.shutter_s;
  data["ambient_radiance"] = scene.studio.ambient_lx / external::kCandelaPerBlenderUnit / kPi;
  // The sensor width that gives the canvas's fx at the true focal length, so that Cycles' pupil
  // (focal length / f-number) is the real one.
  const double focal_mm = camera.focal_length_m * 1000;
  // A pixel's height over its width as angles (fx / fy differs from 1 when the sensor's size in mm
  // is rounded): Blender's pixel aspect, which it takes as two values of at least 1 each. With
  // the sensor fitted horizontally, both shifts are in units of the image's width, and the
  // vertical one in pixels of that aspect.
  const double pixel_height_over_width = canvas.fx / canvas.fy;
  data["camera"] = {
      {"focal_mm", focal_mm},
      {"sensor_width_mm", canvas.width * focal_mm / canvas.fx},
      {"pixel_aspect_x", std::max(1.0, 1 / pixel_height_over_width)},
      {"pixel_aspect_y", std::max(1.0, pixel_height_over_width)},
      {"shift_x", (canvas.width / 2.0 - canvas.cx) / canvas.width},
      {"shift_y", (canvas.cy - canvas.height / 2.0) * pixel_height_over_width / canvas.width},
      {"f_number", camera.aperture_f_number},
      {"depth_of_field", camera.effects.depth_of_field}};

  json materials = json::array();
  for (int m = 0; m < total_materials; ++m) {
    const bool is_object = m < object_materials;
    materials.push_back(material_json(scene, studio.materials[m], m, is_object,
                                      is_object && !studio.object.colors.empty()));
  }
  data["materials"] = materials;
  // scene/speckle.h's constants, for the script's speckle node group.
  namespace sp = scene::speckle;
  data["speckle"] = {{"prime", sp::kPrime},
                     {"dot_starts", sp::kDotStarts},
                     {"radius_min", sp::kRadiusMin},
                     {"radius_span", sp::kRadiusSpan},
                     {"edge", sp::kEdge}};
  namespace nz = scene::noise;
  data["noise"] = {{"frequencies", nz::kFrequencies},
                   {"amplitudes", nz::kAmplitudes},
                   {"amplitude_sum", nz::kAmplitudeSum}};
  data["albedo_only"] = albedo_only;
  data["max_bounces"] = max_bounces;
  for (size_t t = 0; t < scene.textures.size(); ++t) {
    if (!write_linear_texture(dir / texture_file_name(static_cast<int>(t)), scene.textures[t],
                              error)) {
      return false;
    }
  }
  std::string bytes;
  data["geometry_file"] = "geometry.bin";
  data["geometry"]["object"] = append_geometry(bytes, studio.object, 0, object_materials);
  data["geometry"]["studio"] =
      append_geometry(bytes, studio.studio, object_materials, total_materials - object_materials);
  if (!rigc::write_file_atomically(dir / "geometry.bin", bytes, error)) return false;

  json lights = json::array();
  for (size_t l = 0; l < scene.studio.lights.size(); ++l) {
    lights.push_back(light_json(scene.studio.lights[l], static_cast<int>(l)));
  }
  data["lights"] = lights;

  // OpenCV camera (+Y down, +Z forward) to Blender's (+Y up, looking down -Z).
  const ir::Mat4 flip = Eigen::Vector4d(1, -1, -1, 1).asDiagonal();
  json shots = json::array();
  for (const auto& shot : scene.shots) {
    // The turntable turns the object about the world Z axis through the table top.
    const ir::Mat4 world_from_object = ir::world_from_object(scene, shot.turntable_angle_rad);
    shots.push_back({{"name", shot.name},
                     {"index", shot.index},
                     {"camera_matrix", matrix_rows(shot.world_from_camera * flip)},
                     {"focus_distance", shot.focus_distance_m},
                     {"object_location", vec3(world_from_object.block<3, 1>(0, 3))},
                     {"angle", std::atan2(world_from_object(1, 0), world_from_object(0, 0))},
                     {"velocity", shot.turntable_velocity_rad_s},
                     {"motion_blur", camera.effects.motion_blur}});
  }
  data["shots"] = shots;
  return rigc::write_file_atomically(dir / "scene.py", script_text(data), error);
}

bool CyclesBackend::render(const ir::Scene& scene, const scene::StudioScene& /*studio*/,
                           const ir::Shot& shot, const run::RenderSettings& settings,
                           const run::ShotFiles& files, run::RenderedShot* out,
                           std::string* error) {
  const fs::path& dir = files.work_dir;
  const double scale = settings.scale;
  const int samples = settings.samples;
  const std::string stem = shot.name;
  std::error_code ec;
  fs::remove(dir / (stem + ".exr"), ec);
  fs::remove(dir / (stem + "_mask.exr"), ec);
  // An absolute script path: Blender resolves relative ones against $PWD, not the working folder.
  const std::string script = fs::absolute(dir / "scene.py").string();
  std::vector<std::string> argv = {"blender",
                                   "-b",
                                   "--factory-startup",
                                   "-noaudio",
                                   "--python-exit-code",
                                   "2",
                                   "--python",
                                   script,
                                   "--",
                                   "--shot",
                                   std::to_string(shot.index)};
  if (samples > 0) {
    argv.push_back("--samples");
    argv.push_back(std::to_string(samples));
  }
  argv.push_back("--seed");
  argv.push_back(std::to_string(cycles_seed(settings.seed, shot.index)));
  const external::ProgramResult result = external::run_program(argv, dir, files.log);
  if (!result.started) {
    *error = result.error;
    return false;
  }
  if (result.exit_code != 0) {
    *error = fmt::format("blender failed with exit code {}", result.exit_code);
    return false;
  }
  const dslr::RenderGeometry canvas = dslr::render_geometry_for(scene.camera, scale);
  external::LinearImage image, mask;
  if (!external::read_linear_image(dir / (stem + ".exr"), &image, error) ||
      !external::read_linear_image(dir / (stem + "_mask.exr"), &mask, error)) {
    return false;
  }
  if (image.width != canvas.width || image.height != canvas.height || mask.width != canvas.width ||
      mask.height != canvas.height || mask.alpha.empty()) {
    *error = fmt::format("Blender wrote {} x {} images, expected {} x {} with alpha", image.width,
                         image.height, canvas.width, canvas.height);
    return false;
  }
  dslr::LinearFrame& frame = out->frame;
  frame.set_intrinsics(canvas);
  frame.rgb = std::move(image.rgb);
  for (float& v : frame.rgb) v *= static_cast<float>(external::kCandelaPerBlenderUnit);
  frame.mask.resize(mask.alpha.size());
  for (size_t i = 0; i < mask.alpha.size(); ++i) frame.mask[i] = mask.alpha[i] >= 0.5f ? 255 : 0;
  out->depth_of_field_rendered = scene.camera.effects.depth_of_field;
  out->subframes = 1;
  return true;
}

}  // namespace rigc::cycles
