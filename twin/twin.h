// `rigc twin PHOTOS -o DIR`: a real capture as a RigC scene (docs/twin.md). The photos' cameras
// (the reference cameras, or COLMAP's registration scaled by a known size), their silhouettes
// (a key on the backdrop, or --masks) carved into a visual hull, the photos projected onto it,
// and a scene whose shots are the real cameras. DIR gets:
//   scene.yaml        the twin, commented: check, render, plan, sweep and studio read it
//   object.ply        the hull with the photos' colours (metres, +Z up, resting on z = 0)
//   eval/             the photos' evaluation (masks, registration) that the twin was made from
//   render/           the twin rendered by the preview from every real camera
//   contact_sheet.png each real photo beside the twin's render of its view
//   twin.json         cameras, hull, colours, lighting, silhouette IoU per photo
//   ring_N.yaml       with --ring-views N: the twin with N views on the real cameras' ring
#pragma once

#include <optional>
#include <ostream>
#include <string>

#include "eval/eval.h"

namespace rigc::twin {

struct TwinOptions {
  std::string photos_dir;
  std::string output_dir;
  std::string reference_cameras;  // any format eval/camera_files.h reads; with intrinsics
  std::string masks_dir;          // masks made elsewhere (else a key on the backdrop)
  int resolution = 192;           // voxels along the hull's longest side
  int max_misses = 0;             // silhouettes a hull point may fall outside (a key's errors)
  std::optional<double> object_height_m;  // the scale of a registration without reference
  std::string colmap = "colmap";
  eval::Matcher matcher = eval::Matcher::automatic;  // a registration's matcher (eval's --matcher)
  bool render = true;  // render the twin from every camera and compare it with the photos
  int ring_views = 0;  // also write ring_N.yaml: N views on the real cameras' ring (a what-if)
  bool quiet = false;
};

// Writes the twin into options.output_dir, progress and errors to `log`. Returns 0, 1 (user
// error: bad options, photos, cameras or masks; too few silhouettes; no backdrop) or 2 (a tool
// failed: COLMAP, the renderer).
int make_twin(const TwinOptions& options, std::ostream& log);

}  // namespace rigc::twin
