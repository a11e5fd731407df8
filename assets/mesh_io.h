// Loading model files into the IR's mesh, materials and textures.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "ir/ir.h"

namespace rigc {

struct LoadedModel {
  ir::Mesh mesh;  // triangle_material indexes `materials`
  std::vector<ir::Material> materials;
  std::vector<ir::Texture> textures;  // Material::base_color_texture indexes this
  // Linear RGB per vertex of `mesh` (PLY scans), empty if none: the base colour where the scene
  // keeps it (ir::Mesh::colors). The materials have their area-weighted mean as base_color.
  std::vector<Eigen::Vector3f> vertex_colors;
  std::vector<std::string> warnings;  // what loaded but not as the file meant (one line each)
};

// Loads glTF 2.0 (.gltf/.glb, through tinygltf, with base-colour textures) or OBJ/PLY/STL (through
// Assimp). Applies the file's node transforms so the mesh is in the file's scene frame; glTF's +Y
// up is converted to RigC's +Z up (x, y, z) -> (x, -z, y). On failure returns nullopt and sets
// *error to one line that names the file and says what is wrong (no crash, no silent empty mesh).
std::optional<LoadedModel> load_model(const std::string& path, std::string* error);

// Writes a mesh as binary little-endian PLY (positions, normals, uvs and colours as 8-bit sRGB if
// any). For benchmarks, coverage output and twins. Returns false and sets *error on failure.
bool write_ply(const std::string& path, const ir::Mesh& mesh, std::string* error);

}  // namespace rigc
