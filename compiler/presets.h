// Camera body and lens presets: published sensor sizes and resolutions, sensor noise figures,
// and lenses' focal lengths, apertures and closest focus as their makers publish them.
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

// A lens: a prime when the shortest and longest focal lengths are equal, else a zoom (all presets
// here keep their widest aperture through the zoom range).
struct LensPreset {
  std::string name;  // as written in scene files
  std::string model;
  double shortest_focal_m;
  double longest_focal_m;
  double widest_f_number;     // maximum aperture, e.g. 1.8
  double narrowest_f_number;  // minimum aperture, e.g. 22
  double min_focus_m;         // closest focus distance, from the sensor plane
  bool zoom() const { return longest_focal_m > shortest_focal_m; }
};

const std::vector<LensPreset>& lens_presets();
std::optional<LensPreset> find_lens_preset(const std::string& name);

}  // namespace rigc
