// Camera body presets: published sensor sizes and resolutions, and sensor noise figures.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "ir/ir.h"

namespace rigc {

struct BodyPreset {
  std::string name;  // as written in scene files
  std::string make;  // as cameras write it in EXIF
  std::string model;
  double sensor_width_m;
  double sensor_height_m;
  int width_px;
  int height_px;
  ir::SensorNoise noise;
};

const std::vector<BodyPreset>& body_presets();
std::optional<BodyPreset> find_body_preset(const std::string& name);

}  // namespace rigc
