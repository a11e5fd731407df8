// The twin as scene text: a commented rigc: 1 scene whose object is the hull, whose camera is
// the photos' (by its intrinsics) and whose shots are the real cameras (by position and
// rotation), with a studio guessed from the photos for the user to edit (docs/twin.md).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "eval/geometry.h"
#include "ir/ir.h"

namespace rigc::twin {

struct TwinLights {
  double ambient_lux = 300;
  double key_power_w = 60;
  ir::Vec3 key_position{0, -1, 1.2};  // world frame
};

struct TwinScene {
  std::string name;
  std::string source;     // where the photos and cameras came from, for the header
  std::string mesh_file;  // relative to the scene file
  ir::Vec3 object_size{0, 0, 0};
  ir::Vec3 backdrop_linear{0, 0, 0};
  double table_height_m = 0.75;
  double table_diameter_m = 0.1;
  TwinLights lights;
  eval::ViewCamera camera;  // the intrinsics every shot shares
  // The real cameras in the object frame, with their photos' names.
  std::vector<std::pair<std::string, eval::ViewCamera>> shots;
};

std::string scene_yaml(const TwinScene& twin);

}  // namespace rigc::twin
