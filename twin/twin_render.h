// The twin against the photos it was made from: rendered by the preview from every real camera
// (its lights first scaled so that the object is as bright as in the photos), each photo beside
// its render in a contact sheet, and each render's silhouette against the photo's (IoU).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "eval/geometry.h"
#include "twin/scene_text.h"
#include "twin/visual_hull.h"

namespace rigc::twin {

// One photo of the capture: its camera (the capture's frame), silhouette and linear colours.
struct CapturedPhoto {
  std::string name;
  eval::ViewCamera camera;
  Silhouette silhouette;
  std::vector<Eigen::Vector3f> linear;
};

// Renders the twin at `scene_path` (written from `scene`, in shot order of `photos`) into
// OUT/render, rewriting the scene with its lights scaled to the photos' brightness; writes
// OUT/contact_sheet.png and report["comparison"]. 0, or 2 with `error` (the scene did not
// compile or a shot failed to render).
// (Seven parameters: the twin being made and where its renders go, as twin.cpp holds them.)
int render_and_compare(const std::filesystem::path& scene_path, TwinScene& scene,
                       const std::vector<CapturedPhoto>& photos, const std::filesystem::path& out,
                       nlohmann::json& report, std::ostream& log, std::string* error);

}  // namespace rigc::twin
