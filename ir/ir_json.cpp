#include "ir/ir_json.h"

#include "ir/utf8_text.h"

namespace rigc {
namespace {

using nlohmann::json;

json loc_json(const SourceLoc& loc) {
  return json{{"file", loc.file}, {"line", loc.line}, {"col", loc.col}};
}

json vec_json(const ir::Vec3& v) {
  return json::array({v.x(), v.y(), v.z()});
}

json mat_json(const ir::Mat4& m) {
  json rows = json::array();
  for (int r = 0; r < 4; ++r) {
    rows.push_back(json::array({m(r, 0), m(r, 1), m(r, 2), m(r, 3)}));
  }
  return rows;
}

const char* pattern_name(ir::PatternKind kind) {
  switch (kind) {
    case ir::PatternKind::kNone:
      return "none";
    case ir::PatternKind::kSpeckle:
      return "speckle";
    case ir::PatternKind::kNoise:
      return "noise";
    case ir::PatternKind::kChecker:
      return "checker";
  }
  return "none";
}

const char* light_type_name(ir::LightType type) {
  switch (type) {
    case ir::LightType::kPoint:
      return "point";
    case ir::LightType::kSpot:
      return "spot";
    case ir::LightType::kDirectional:
      return "directional";
    case ir::LightType::kArea:
      return "area";
  }
  return "point";
}

const char* shot_kind_name(ir::ShotKind kind) {
  switch (kind) {
    case ir::ShotKind::kTurntable:
      return "turntable";
    case ir::ShotKind::kOrbit:
      return "orbit";
    case ir::ShotKind::kPose:
      return "pose";
  }
  return "pose";
}

const char* format_name(ir::ImageFormat format) {
  switch (format) {
    case ir::ImageFormat::kJpeg:
      return "jpeg";
    case ir::ImageFormat::kPng16:
      return "png16";
    case ir::ImageFormat::kTiff16:
      return "tiff16";
  }
  return "jpeg";
}

json mesh_json(const ir::Mesh& mesh, bool include_geometry) {
  json out{{"vertex_count", mesh.positions.size()},
           {"triangle_count", mesh.triangles.size()},
           {"has_uvs", !mesh.uvs.empty()},
           {"has_vertex_colors", !mesh.colors.empty()}};
  if (!include_geometry) return out;
  std::vector<float> positions, normals, uvs;
  positions.reserve(mesh.positions.size() * 3);
  for (const auto& p : mesh.positions) positions.insert(positions.end(), {p.x(), p.y(), p.z()});
  normals.reserve(mesh.normals.size() * 3);
  for (const auto& n : mesh.normals) normals.insert(normals.end(), {n.x(), n.y(), n.z()});
  uvs.reserve(mesh.uvs.size() * 2);
  for (const auto& uv : mesh.uvs) uvs.insert(uvs.end(), {uv.x(), uv.y()});
  std::vector<float> colors;
  colors.reserve(mesh.colors.size() * 3);
  for (const auto& c : mesh.colors) colors.insert(colors.end(), {c.x(), c.y(), c.z()});
  std::vector<std::uint32_t> indices;
  indices.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles) indices.insert(indices.end(), t.begin(), t.end());
  out["positions"] = positions;
  out["normals"] = normals;
  out["uvs"] = uvs;
  out["vertex_colors"] = colors;
  out["triangles"] = indices;
  out["triangle_material"] = mesh.triangle_material;
  return out;
}

json object_json(const ir::Object& object, bool include_geometry) {
  return {{"source", object.source},
          {"object_from_mesh", mat_json(object.object_from_mesh)},
          {"bounds_min_object", vec_json(object.bounds_min_object)},
          {"bounds_max_object", vec_json(object.bounds_max_object)},
          {"mesh", mesh_json(object.mesh, include_geometry)},
          {"loc", loc_json(object.loc)}};
}

json materials_json(const std::vector<ir::Material>& materials) {
  json out = json::array();
  for (const auto& m : materials) {
    out.push_back({{"name", m.name},
                   {"base_color", vec_json(m.base_color)},
                   {"base_color_texture", m.base_color_texture},
                   {"roughness", m.roughness},
                   {"metallic", m.metallic},
                   {"pattern",
                    {{"kind", pattern_name(m.pattern.kind)},
                     {"scale_m", m.pattern.scale_m},
                     {"contrast", m.pattern.contrast},
                     {"seed", m.pattern.seed}}},
                   {"loc", loc_json(m.loc)}});
  }
  return out;
}

// The textures' sources and sizes (not their pixels).
json textures_json(const std::vector<ir::Texture>& textures) {
  json out = json::array();
  for (const auto& t : textures) {
    out.push_back(
        {{"source", t.source}, {"width", t.width}, {"height", t.height}, {"channels", t.channels}});
  }
  return out;
}

json lights_json(const std::vector<ir::Light>& lights) {
  json out = json::array();
  for (const auto& l : lights) {
    out.push_back({{"type", light_type_name(l.type)},
                   {"position", vec_json(l.position)},
                   {"direction", vec_json(l.direction)},
                   {"power_w", l.power_w},
                   {"illuminance_lx", l.illuminance_lx},
                   {"temperature_k", l.temperature_k},
                   {"color", vec_json(l.color)},
                   {"size_m", json::array({l.size_m.x(), l.size_m.y()})},
                   {"spot_angle_rad", l.spot_angle_rad},
                   {"spot_blend", l.spot_blend},
                   {"loc", loc_json(l.loc)}});
  }
  return out;
}

json studio_json(const ir::Studio& studio) {
  return {{"turntable",
           {{"diameter_m", studio.turntable.diameter_m},
            {"height_m", studio.turntable.height_m},
            {"thickness_m", studio.turntable.thickness_m},
            {"color", vec_json(studio.turntable.color)},
            {"loc", loc_json(studio.turntable.loc)}}},
          {"backdrop",
           {{"green_screen", studio.backdrop.green_screen},
            {"color", vec_json(studio.backdrop.color)},
            {"distance_m", studio.backdrop.distance_m},
            {"direction", vec_json(studio.backdrop.direction)},
            {"width_m", studio.backdrop.width_m},
            {"height_m", studio.backdrop.height_m},
            {"loc", loc_json(studio.backdrop.loc)}}},
          {"lights", lights_json(studio.lights)},
          {"ambient_lx", studio.ambient_lx},
          {"floor_color", vec_json(studio.floor_color)}};
}

json noise_json(const ir::SensorNoise& noise) {
  return {{"full_well_e", noise.full_well_e},
          {"base_iso", noise.base_iso},
          {"read_noise_e", noise.read_noise_e},
          {"read_noise_high_iso_e", noise.read_noise_high_iso_e},
          {"prnu", noise.prnu},
          {"dsnu_e", noise.dsnu_e},
          {"dark_current_e_per_s", noise.dark_current_e_per_s},
          {"adc_bits", noise.adc_bits},
          {"source_note", noise.source_note}};
}

json camera_json(const ir::Camera& c) {
  return {{"body", c.body},
          {"make", c.make},
          {"model", c.model},
          {"sensor_width_m", c.sensor_width_m},
          {"sensor_height_m", c.sensor_height_m},
          {"width_px", c.width_px},
          {"height_px", c.height_px},
          {"focal_length_m", c.focal_length_m},
          {"model_name", "OPENCV"},
          {"intrinsics", {{"fx", c.fx}, {"fy", c.fy}, {"cx", c.cx}, {"cy", c.cy}}},
          {"distortion",
           {{"k1", c.distortion.k1},
            {"k2", c.distortion.k2},
            {"p1", c.distortion.p1},
            {"p2", c.distortion.p2},
            {"k3", c.distortion.k3}}},
          {"vignetting", c.vignetting},
          {"aperture_f_number", c.aperture_f_number},
          {"shutter_s", c.shutter_s},
          {"iso", c.iso},
          {"white_balance",
           c.white_balance == ir::WhiteBalanceMode::kAuto ? json("auto") : json(c.white_balance_k)},
          {"noise", noise_json(c.noise)},
          {"effects",
           {{"depth_of_field", c.effects.depth_of_field},
            {"diffraction", c.effects.diffraction},
            {"motion_blur", c.effects.motion_blur},
            {"distortion", c.effects.distortion},
            {"vignetting", c.effects.vignetting},
            {"noise", c.effects.noise}}},
          {"format", format_name(c.format)},
          {"jpeg_quality", c.jpeg_quality},
          {"circle_of_confusion_m", c.circle_of_confusion_m},
          {"loc", loc_json(c.loc)}};
}

json shots_json(const std::vector<ir::Shot>& shots) {
  json out = json::array();
  for (const auto& s : shots) {
    out.push_back({{"index", s.index},
                   {"name", s.name},
                   {"kind", shot_kind_name(s.kind)},
                   {"world_from_camera", mat_json(s.world_from_camera)},
                   {"object_from_camera", mat_json(s.object_from_camera)},
                   {"turntable_angle_rad", s.turntable_angle_rad},
                   {"turntable_velocity_rad_s", s.turntable_velocity_rad_s},
                   {"focus_distance_m", s.focus_distance_m},
                   {"loc", loc_json(s.loc)}});
  }
  return out;
}

json coverage_json(const ir::CoverageSettings& cov) {
  return {{"min_pixels_per_mm2", cov.min_pixels_per_mm2},
          {"max_view_angle_rad", cov.max_view_angle_rad},
          {"max_blur_px", cov.max_blur_px},
          {"min_triangulation_angle_rad", cov.min_triangulation_angle_rad},
          {"min_signal", cov.min_signal},
          {"max_signal", cov.max_signal},
          {"min_overlap", cov.min_overlap},
          {"min_frame_fill", cov.min_frame_fill}};
}

// Replaces the bytes of every key and string under `node` that are not UTF-8: the IR's file names
// and material names come from the file system and from MTL files, and json::dump throws on them.
void make_text_valid_utf8(json& node) {
  if (node.is_string()) {
    std::string& text = node.get_ref<std::string&>();
    if (!valid_utf8(text)) text = valid_utf8_text(text);
  } else if (node.is_array()) {
    for (auto& item : node) {
      if (!item.is_primitive() || item.is_string()) make_text_valid_utf8(item);
    }
  } else if (node.is_object()) {
    json fixed = json::object();
    for (auto& [key, value] : node.items()) {
      make_text_valid_utf8(value);
      fixed[valid_utf8_text(key)] = std::move(value);
    }
    node = std::move(fixed);
  }
}

}  // namespace

json ir_to_json(const ir::Scene& scene, bool include_geometry) {
  json out;
  out["rigc_ir"] = 1;
  out["units"] = "SI: meters, radians, seconds, kelvin, watts, lux";
  out["frames"] =
      "world: floor z=0, +Z up; object: turntable top centre, rotates about +Z; camera: OpenCV "
      "(+X right, +Y down, +Z forward)";
  out["language_version"] = scene.language_version;
  out["name"] = scene.name;
  out["source_file"] = scene.source_file;
  out["object"] = object_json(scene.object, include_geometry);
  out["materials"] = materials_json(scene.materials);
  out["textures"] = textures_json(scene.textures);
  out["studio"] = studio_json(scene.studio);
  out["camera"] = camera_json(scene.camera);
  out["shots"] = shots_json(scene.shots);
  out["coverage"] = coverage_json(scene.coverage);
  make_text_valid_utf8(out);
  return out;
}

}  // namespace rigc
