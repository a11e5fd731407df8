#include "fuzz/entries.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>

#include "assets/mesh_io.h"
#include "assets/model_loading.h"
#include "assets/textures.h"
#include "compiler/frontend.h"
#include "fuzz/input_file.h"
#include "run/colmap_text.h"
#include "run/manifest.h"

namespace rigc::fuzz {

namespace fs = std::filesystem;

// A folder of this process's own for the inputs the readers want as files, removed at exit.
const std::filesystem::path& input_dir() {
  static const fs::path dir = [] {
    fs::path d = fs::temp_directory_path() / ("rigc-fuzz-" + std::to_string(::getpid()));
    fs::create_directories(d);
    std::atexit([] {
      std::error_code ec;
      fs::remove_all(input_dir(), ec);
    });
    return d;
  }();
  return dir;
}

// Writes `input` to the file `name` in input_dir() and returns its path.
std::filesystem::path write_input(std::string_view input, const std::string& name) {
  const fs::path path = input_dir() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(input.data(), static_cast<std::streamsize>(input.size()));
  if (!out.flush()) throw std::runtime_error("fuzz: cannot write " + path.string());
  return path;
}

namespace {

// A model loads or fails with a one-line error naming the file; it never comes back empty.
void load_model_file(std::string_view input, const std::string& name) {
  std::string error;
  const std::optional<LoadedModel> model = load_model(write_input(input, name).string(), &error);
  if (!model && (error.empty() || error.find('\n') != std::string::npos)) {
    throw std::logic_error("load_model failed without a one-line error: " + error);
  }
  if (model && model->mesh.triangles.empty()) {
    throw std::logic_error("load_model returned a mesh without triangles");
  }
}

}  // namespace

void scene(std::string_view input) {
  DiagnosticEngine diag;
  std::size_t rendered_bytes = 0;
  diag.set_handler(
      [&](const Diagnostic&, const std::string& rendered) { rendered_bytes += rendered.size(); });
  const std::optional<ir::Scene> ir = compile_scene_text(
      std::string(input), "fuzz.yaml", std::string(RIGC_SOURCE_DIR) + "/scenes", diag);
  if (!ir && !diag.has_errors()) throw std::logic_error("a scene failed without an error");
}

void ply(std::string_view input) {
  load_model_file(input, "model.ply");
}
void obj(std::string_view input) {
  load_model_file(input, "model.obj");
}
void stl(std::string_view input) {
  load_model_file(input, "model.stl");
}

void gltf(std::string_view input) {
  load_model_file(input, input.substr(0, 4) == "glTF" ? "model.glb" : "model.gltf");
}

void texture(std::string_view input) {
  try {
    const ir::Texture tex = loading::decode_image(
        "fuzz.png", std::vector<unsigned char>(input.begin(), input.end()), "fuzz.png");
    if (tex.pixels.size() != static_cast<std::size_t>(tex.width) * tex.height * tex.channels) {
      throw std::logic_error("a texture's pixels do not match its size");
    }
  } catch (const loading::LoadError&) {
    // A clear refusal is what the decoder should give bad bytes.
  }
}

void colmap_cameras(std::string_view input) {
  std::string error;
  const auto cameras = run::read_colmap_cameras(write_input(input, "cameras.txt"), &error);
  require_error_if_failed(cameras, error);
  if (!cameras) return;
  for (const run::ColmapCamera& camera : *cameras) {
    run::project_opencv(camera.params, ir::Mat4::Identity(), ir::Vec3(0.1, 0.2, 1.0));
  }
}

void colmap_images(std::string_view input) {
  std::string error;
  require_error_if_failed(run::read_colmap_images(write_input(input, "images.txt"), &error), error);
}

void manifest(std::string_view input) {
  const fs::path path = write_input(input, "manifest.json");
  const run::Manifest loaded = run::Manifest::load(path);
  for (const auto& [name, record] : loaded.shots()) {
    loaded.is_done(name, record.key, input_dir());
  }
  loaded.to_json().dump();
}

}  // namespace rigc::fuzz
