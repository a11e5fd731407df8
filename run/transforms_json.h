// transforms.json: the ground-truth cameras for NeRF / Gaussian-splatting tools (nerfstudio's
// format). The world is the object frame, as in the COLMAP model.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "ir/ir.h"

namespace rigc::run {

// object_from_camera in the OpenGL/Blender camera convention (+X right, +Y up, +Z backward):
// the OpenCV pose with its Y and Z columns negated.
ir::Mat4 opengl_object_from_camera(const ir::Shot& shot);

// The document: camera_model "OPENCV", fl_x fl_y cx cy w h k1 k2 k3 p1 p2 (of output_camera at
// `scale`), and frames [{file_path: "images/shot_000.jpg", mask_path: "masks/shot_000.png",
// colmap_im_id: index + 1, transform_matrix: opengl_object_from_camera rows}].
// Fails (one-line `error`) on a bad scale or shot index.
bool make_transforms_json(const ir::Scene& scene, const std::vector<int>& shots, double scale,
                          nlohmann::json* out, std::string* error);

// make_transforms_json written atomically to `path` (its folder must exist).
bool write_transforms_json(const std::filesystem::path& path, const ir::Scene& scene,
                           const std::vector<int>& shots, double scale, std::string* error);

}  // namespace rigc::run
