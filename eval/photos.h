// What a folder of photos needs before COLMAP, which a run folder has from its renderer: object
// masks (eval/photo_masks.h), the cameras and their intrinsics priors (eval/photo_camera.h) and
// the order the photos were taken in, for sequential matching.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "eval/eval.h"
#include "eval/inputs.h"
#include "eval/photo_camera.h"
#include "eval/photo_masks.h"

namespace rigc::eval {

struct PhotoSetup {
  PhotoMasks masks;
  std::vector<PhotoCamera> cameras;
  std::vector<std::string> order;  // the photos in capture order
  std::string order_basis;         // "EXIF time taken" or "file names"
};

// Masks (unless --no-masks), cameras and capture order of the photos in `inputs`, written into
// OUT. nullopt with `error` for a user error (a bad --camera or --masks).
std::optional<PhotoSetup> prepare_photos(const EvalOptions& options, const EvalInputs& inputs,
                                         std::ostream& log, std::string* error);

// The images that did not register and their probable causes (eval/photo_diagnosis.h), one line
// each on the log: eval.json's "unregistered" section (an empty object when all registered).
// `setup` is null for a run folder; `masked` says whether COLMAP had object masks.
nlohmann::json report_unregistered(const EvalInputs& inputs, const PhotoSetup* setup,
                                   const std::set<std::string>& registered, bool masked,
                                   std::ostream& log);

}  // namespace rigc::eval
