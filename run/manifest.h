// manifest.json: what a run rendered, from which inputs, and how long it took. A rerun skips the
// shots whose entry has the same key and whose files are all still there.
//
//   {"rigc_version": "0.1.0", "backend": "preview", "inputs": {...},
//    "shots": {"shot_000": {"key": "...", "render_ms": 812.5, "stage_ms": {...},
//                           "files": ["images/shot_000.jpg", "masks/shot_000.png"],
//                           "scale": 0.25, "seed": 1}}}
// inputs.scale and inputs.seed are the last run's; a shot's own entry says what its files have.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "ir/ir.h"

namespace rigc::run {

struct ShotRecord {
  std::string name;  // shot_000
  std::string key;   // shot_key: a hash of everything that determines this shot's files
  double render_ms = 0;
  std::map<std::string, double> stage_ms;
  std::vector<std::string> files;  // written files, relative to the run folder
  // The render scale and noise seed of this shot's files (a rerun of some shots may use others).
  std::optional<double> scale;
  std::optional<std::uint64_t> seed;
};

class Manifest {
 public:
  // A missing, unreadable or corrupt file gives an empty manifest (everything re-renders);
  // malformed shot entries are dropped. Never throws.
  static Manifest load(const std::filesystem::path& path);

  // True when the entry for `name` has this (non-empty) key and every file it lists exists in
  // run_dir and is not empty.
  bool is_done(const std::string& name, const std::string& key,
               const std::filesystem::path& run_dir) const;
  // Adds or replaces the entry for record.name.
  void record(ShotRecord record);
  void forget(const std::string& name) { shots_.erase(name); }

  // Scene name, source file, inputs' hashes, backend, scale, seed...: for people and tools.
  void set_inputs(nlohmann::json inputs) { inputs_ = std::move(inputs); }
  void set_backend(std::string backend) { backend_ = std::move(backend); }

  const nlohmann::json& inputs() const { return inputs_; }
  const std::string& backend() const { return backend_; }
  // The version that wrote the loaded file; save() writes this build's RIGC_VERSION.
  const std::string& rigc_version() const { return rigc_version_; }
  const std::map<std::string, ShotRecord>& shots() const { return shots_; }
  const ShotRecord* find(const std::string& name) const;
  // The seconds every recorded shot took to render, summed.
  double render_seconds() const;

  nlohmann::json to_json() const;
  // Atomic write; false with a one-line `error`.
  bool save(const std::filesystem::path& path, std::string* error) const;

 private:
  std::string rigc_version_;
  std::string backend_;
  nlohmann::json inputs_ = nlohmann::json::object();
  std::map<std::string, ShotRecord> shots_;
};

// SHA-256 of the scene's bulk data, which ir_to_json(include_geometry = false) leaves out: mesh
// positions, normals, uvs, triangles and triangle materials, and texture pixels. Compute it once
// per scene and pass it to shot_key.
std::string scene_content_hash(const ir::Scene& scene);

// SHA-256 of the object's surface in its own frame (ir::object_frame_positions and the
// triangles): what eval measures a reconstruction against. Unlike the content hash it follows
// fit/scale/rotate and ignores textures.
std::string object_geometry_hash(const ir::Scene& scene);

// The key of one shot's output: SHA-256 over the IR of everything that can change its image
// (object placement, materials, textures, studio, camera and this shot; not the other shots, the
// scene name or source locations), `content_hash`, the backend, scale, seed, `extra` (backend
// options) and the rigc version.
// (Seven parameters: every input of the key, as the manifest names them.)
std::string shot_key(const ir::Scene& scene, const std::string& content_hash, const ir::Shot& shot,
                     const std::string& backend, double scale, std::uint64_t seed,
                     const std::string& extra = "");

}  // namespace rigc::run
