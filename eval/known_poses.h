// Points from the photos' features with the cameras held where reference cameras put them
// (COLMAP's point_triangulator): what a reconstruction would hold had SfM registered every photo
// as the reference has it. `rigc eval --reference-cameras` runs it when SfM registers too few.
#pragma once

#include <filesystem>
#include <ostream>
#include <string>

#include "eval/camera_files.h"
#include "eval/colmap.h"
#include "eval/eval.h"
#include "eval/inputs.h"

namespace rigc::eval {

// The reference as a COLMAP text model of the database's image and camera ids (no points):
// PINHOLE cameras from the reference intrinsics (a database camera shared by several photos
// takes its first photo's). False with `error` when a photo of the database has no reference
// camera or no intrinsics.
bool write_known_model(const std::filesystem::path& database, const KnownCameras& reference,
                       const std::filesystem::path& model_dir, std::string* error);

// After run_colmap's features and matches (`sfm`), the points triangulated with the reference
// poses and intrinsics fixed, in OUT/colmap/known_poses (model_txt: its text form). The steps are
// logged to OUT/logs like run_colmap's.
ColmapRun triangulate_known_poses(const EvalOptions& options, const EvalInputs& inputs,
                                  const ColmapRun& sfm, std::ostream& log);

}  // namespace rigc::eval
