#include "run/manifest.h"

#include <fstream>
#include <sstream>
#include <system_error>

#include "io/bounded_file.h"
#include "io/files.h"
#include "ir/ir_json.h"

#ifndef RIGC_VERSION
#define RIGC_VERSION "unknown"
#endif

namespace rigc::run {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::optional<ShotRecord> record_from_json(const std::string& name, const json& j) {
  if (!j.is_object() || !j.contains("key") || !j["key"].is_string()) return std::nullopt;
  ShotRecord record;
  record.name = name;
  record.key = j["key"].get<std::string>();
  if (auto it = j.find("render_ms"); it != j.end() && it->is_number()) {
    record.render_ms = it->get<double>();
  }
  if (auto it = j.find("stage_ms"); it != j.end() && it->is_object()) {
    for (const auto& [stage, ms] : it->items()) {
      if (ms.is_number()) record.stage_ms[stage] = ms.get<double>();
    }
  }
  if (auto it = j.find("scale"); it != j.end() && it->is_number()) record.scale = it->get<double>();
  if (auto it = j.find("seed"); it != j.end() && it->is_number_unsigned()) {
    record.seed = it->get<std::uint64_t>();
  }
  const auto files = j.find("files");
  if (files == j.end() || !files->is_array()) return std::nullopt;
  for (const auto& file : *files) {
    if (!file.is_string()) return std::nullopt;
    record.files.push_back(file.get<std::string>());
  }
  return record;
}

}  // namespace

Manifest Manifest::load(const fs::path& path) {
  Manifest manifest;
  try {
    // A manifest of thousands of shots is a few megabytes; a pipe or device in its place is none.
    constexpr std::size_t kMostManifestBytes = std::size_t{64} << 20;
    std::string why;
    const auto file = read_bounded_file(path, kMostManifestBytes, &why);
    if (!file) return manifest;
    const json j = json::parse(file->bytes, nullptr, /*allow_exceptions=*/false);
    if (!j.is_object()) return manifest;
    if (auto it = j.find("rigc_version"); it != j.end() && it->is_string()) {
      manifest.rigc_version_ = it->get<std::string>();
    }
    if (auto it = j.find("backend"); it != j.end() && it->is_string()) {
      manifest.backend_ = it->get<std::string>();
    }
    if (auto it = j.find("inputs"); it != j.end() && it->is_object()) manifest.inputs_ = *it;
    if (auto it = j.find("shots"); it != j.end() && it->is_object()) {
      for (const auto& [name, entry] : it->items()) {
        auto record = record_from_json(name, entry);
        if (!record) continue;
        // Written before shots had their own: the run's values were every shot's.
        const json& inputs = manifest.inputs_;
        if (!record->scale && inputs.contains("scale") && inputs["scale"].is_number()) {
          record->scale = inputs["scale"].get<double>();
        }
        if (!record->seed && inputs.contains("seed") && inputs["seed"].is_number_unsigned()) {
          record->seed = inputs["seed"].get<std::uint64_t>();
        }
        manifest.shots_[name] = std::move(*record);
      }
    }
  } catch (...) {
    return Manifest{};
  }
  return manifest;
}

const ShotRecord* Manifest::find(const std::string& name) const {
  const auto it = shots_.find(name);
  return it == shots_.end() ? nullptr : &it->second;
}

double Manifest::render_seconds() const {
  double ms = 0;
  for (const auto& [name, shot] : shots_) ms += shot.render_ms;
  return ms / 1000;
}

bool Manifest::is_done(const std::string& name, const std::string& key,
                       const fs::path& run_dir) const {
  const ShotRecord* record = find(name);
  if (record == nullptr || record->key != key || key.empty()) return false;
  for (const auto& file : record->files) {
    // An empty file is no image (a disk that filled up, a file truncated by hand).
    std::error_code ec;
    if (!fs::is_regular_file(run_dir / file, ec)) return false;
    const auto bytes = fs::file_size(run_dir / file, ec);
    if (ec || bytes == 0) return false;
  }
  return true;
}

void Manifest::record(ShotRecord record) {
  std::string name = record.name;
  shots_[name] = std::move(record);
}

json Manifest::to_json() const {
  json shots = json::object();
  for (const auto& [name, record] : shots_) {
    shots[name] = {{"key", record.key},
                   {"render_ms", record.render_ms},
                   {"stage_ms", record.stage_ms},
                   {"files", record.files}};
    if (record.scale) shots[name]["scale"] = *record.scale;
    if (record.seed) shots[name]["seed"] = *record.seed;
  }
  return {
      {"rigc_version", RIGC_VERSION}, {"backend", backend_}, {"inputs", inputs_}, {"shots", shots}};
}

bool Manifest::save(const fs::path& path, std::string* error) const {
  // Text from the user's files (a scene or texture name) may hold bytes that are not UTF-8: each
  // becomes U+FFFD rather than an exception.
  const std::string text = to_json().dump(2, ' ', false, json::error_handler_t::replace) + "\n";
  return write_file_atomically(path, text, error);
}

std::string scene_content_hash(const ir::Scene& scene) {
  static_assert(sizeof(Eigen::Vector3f) == 12 && sizeof(Eigen::Vector2f) == 8);
  static_assert(sizeof(std::array<std::uint32_t, 3>) == 12);
  Sha256 hash;
  // Each array is preceded by its byte count, so bytes cannot move between arrays unnoticed.
  auto add = [&](const void* data, std::uint64_t bytes) {
    hash.update(&bytes, sizeof bytes);
    if (bytes > 0) hash.update(data, bytes);
  };
  const ir::Mesh& mesh = scene.object.mesh;
  add(mesh.positions.data(), mesh.positions.size() * sizeof(Eigen::Vector3f));
  add(mesh.normals.data(), mesh.normals.size() * sizeof(Eigen::Vector3f));
  add(mesh.uvs.data(), mesh.uvs.size() * sizeof(Eigen::Vector2f));
  // Only when present, so that the keys of runs of meshes without colours stay as they were.
  if (!mesh.colors.empty()) add(mesh.colors.data(), mesh.colors.size() * sizeof(Eigen::Vector3f));
  add(mesh.triangles.data(), mesh.triangles.size() * sizeof(mesh.triangles[0]));
  add(mesh.triangle_material.data(), mesh.triangle_material.size() * sizeof(std::int32_t));
  const std::uint64_t texture_count = scene.textures.size();
  hash.update(&texture_count, sizeof texture_count);
  for (const auto& texture : scene.textures) {
    const std::int32_t shape[3] = {texture.width, texture.height, texture.channels};
    hash.update(shape, sizeof shape);
    add(texture.pixels.data(), texture.pixels.size());
  }
  return hash.hex_digest();
}

std::string object_geometry_hash(const ir::Scene& scene) {
  Sha256 hash;
  const std::vector<Eigen::Vector3f> positions = ir::object_frame_positions(scene.object);
  const std::uint64_t counts[2] = {positions.size(), scene.object.mesh.triangles.size()};
  hash.update(counts, sizeof counts);
  if (!positions.empty()) hash.update(positions.data(), positions.size() * sizeof(positions[0]));
  const auto& triangles = scene.object.mesh.triangles;
  if (!triangles.empty()) hash.update(triangles.data(), triangles.size() * sizeof(triangles[0]));
  return hash.hex_digest();
}

namespace {

void strip_locations(json& j) {
  if (j.is_object()) {
    j.erase("loc");
    for (auto& [key, value] : j.items()) strip_locations(value);
  } else if (j.is_array()) {
    for (auto& value : j) strip_locations(value);
  }
}

}  // namespace

std::string shot_key(const ir::Scene& scene, const std::string& content_hash, const ir::Shot& shot,
                     const std::string& backend, double scale, std::uint64_t seed,
                     const std::string& extra) {
  // A copy without the bulk data and the other shots, so that the JSON is small and a shot's key
  // does not depend on its neighbours.
  ir::Scene light;
  light.language_version = scene.language_version;
  light.object.source = scene.object.source;
  light.object.object_from_mesh = scene.object.object_from_mesh;
  light.object.bounds_min_object = scene.object.bounds_min_object;
  light.object.bounds_max_object = scene.object.bounds_max_object;
  light.materials = scene.materials;
  for (const auto& texture : scene.textures) {
    light.textures.push_back({texture.source, texture.width, texture.height, texture.channels, {}});
  }
  light.studio = scene.studio;
  light.camera = scene.camera;
  light.shots = {shot};
  json ir = ir_to_json(light, /*include_geometry=*/false);
  ir.erase("name");
  ir.erase("source_file");
  ir["object"].erase("mesh");  // counts are zero here; content_hash covers the mesh
  strip_locations(ir);
  const json key = {
      {"ir", ir},     {"content", content_hash}, {"backend", backend},          {"scale", scale},
      {"seed", seed}, {"extra", extra},          {"rigc_version", RIGC_VERSION}};
  return sha256_hex(key.dump(-1, ' ', false, json::error_handler_t::replace));
}

}  // namespace rigc::run
