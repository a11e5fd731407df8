#include "run/scene_inputs.h"

#include <filesystem>

#include "io/input_files.h"

namespace rigc::run {

void protect_scene_inputs(const std::string& scene_path, const ir::Scene& scene) {
  protect_input_file(scene_path, "the scene file");
  protect_scene_files(scene);
}

void protect_scene_files(const ir::Scene& scene) {
  const std::string& mesh = scene.object.source;
  if (!mesh.empty() && !mesh.starts_with("primitive:")) {
    protect_input_file(mesh, "the scene's mesh");
    for (const auto& library : obj_material_libraries(mesh)) {
      protect_input_file(library, "the mesh's material library");
    }
  }
  for (const auto& texture : scene.textures) {
    // "model.glb#image3" is an image inside the mesh file.
    protect_input_file(texture.source.substr(0, texture.source.find('#')),
                       "a texture of the scene");
  }
}

}  // namespace rigc::run
