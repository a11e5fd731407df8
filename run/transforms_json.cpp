#include "run/transforms_json.h"

#include <fmt/format.h>

#include "io/files.h"
#include "run/colmap_text.h"

namespace rigc::run {

ir::Mat4 opengl_object_from_camera(const ir::Shot& shot) {
  ir::Mat4 pose = shot.object_from_camera;
  pose.col(1) *= -1;
  pose.col(2) *= -1;
  return pose;
}

bool make_transforms_json(const ir::Scene& scene, const std::vector<int>& shots, double scale,
                          nlohmann::json* out, std::string* error) {
  const auto camera = output_camera(scene.camera, scale, error);
  if (!camera) return false;
  nlohmann::json frames = nlohmann::json::array();
  for (int index : shots) {
    if (index < 0 || index >= static_cast<int>(scene.shots.size())) {
      if (error != nullptr) {
        *error = fmt::format("cannot write transforms.json: shot index {} is out of range (0..{})",
                             index, static_cast<int>(scene.shots.size()) - 1);
      }
      return false;
    }
    const ir::Shot& shot = scene.shots[index];
    const ir::Mat4 pose = opengl_object_from_camera(shot);
    nlohmann::json rows = nlohmann::json::array();
    for (int r = 0; r < 4; ++r) {
      // + 0.0 turns -0 into 0, so that the file does not show "-0.0".
      rows.push_back({pose(r, 0) + 0.0, pose(r, 1) + 0.0, pose(r, 2) + 0.0, pose(r, 3) + 0.0});
    }
    frames.push_back({{"file_path", image_relative_path(scene.camera, shot)},
                      {"mask_path", mask_relative_path(shot)},
                      {"colmap_im_id", index + 1},
                      {"transform_matrix", rows}});
  }
  const ir::Distortion& d = camera->distortion;
  *out = {{"camera_model", "OPENCV"},
          {"fl_x", camera->fx},
          {"fl_y", camera->fy},
          {"cx", camera->cx},
          {"cy", camera->cy},
          {"w", camera->width},
          {"h", camera->height},
          {"k1", d.k1},
          {"k2", d.k2},
          {"k3", d.k3},
          {"p1", d.p1},
          {"p2", d.p2},
          {"frames", frames}};
  return true;
}

bool write_transforms_json(const std::filesystem::path& path, const ir::Scene& scene,
                           const std::vector<int>& shots, double scale, std::string* error) {
  nlohmann::json document;
  if (!make_transforms_json(scene, shots, scale, &document, error)) return false;
  return write_file_atomically(path, document.dump(2) + "\n", error);
}

}  // namespace rigc::run
