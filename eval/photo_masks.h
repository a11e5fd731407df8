// The object masks of a folder of photos, written beside the eval output (OUT/masks/<stem>.png,
// 255 = object): keyed from the pictures (eval/chroma_key.h) or taken from a folder of masks made
// elsewhere (--masks), and a contact sheet (OUT/masks_contact_sheet.png: each photo beside itself
// with what was keyed away tinted) so a user sees what COLMAP was shown.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>

#include "eval/inputs.h"
#include "ir/ir.h"

namespace rigc::eval {

struct PhotoMaskOptions {
  std::string masks_dir;                   // masks made elsewhere: same stems, any common format
  std::optional<ir::Vec3> backdrop_color;  // the scene's green screen (linear RGB), if any
  double tolerance = 0.12;                 // chromaticity distance keyed as the backdrop
  // A keyed outline grows by this much (working pixels, 1024 on the long side) so that COLMAP's
  // features on the silhouette keep their support; 0 for the silhouette itself (a hull).
  int grow_px = 2;
  bool quiet = false;
};

struct PhotoMasks {
  std::filesystem::path dir;  // OUT/masks; empty when no photo got a mask
  std::string contact_sheet;  // OUT/masks_contact_sheet.png, or "" when it could not be written
  nlohmann::json report;      // method, key colour, still background, coverage by photo
};

// The masks of `images` in OUT/masks. nullopt with `error` for a user error (a --masks folder
// without masks for the photos, or a mask of another size); a photo the key cannot mask (no
// backdrop at its borders, nothing still) gets none, which the report says.
std::optional<PhotoMasks> make_photo_masks(const ImageSet& images, const PhotoMaskOptions& options,
                                           const std::filesystem::path& out, std::ostream& log,
                                           std::string* error);

// Each photo beside itself with the pixels its mask leaves out tinted magenta, three pairs a row.
bool write_contact_sheet(const ImageSet& images, const std::filesystem::path& masks_dir,
                         const std::filesystem::path& path, std::string* error);

}  // namespace rigc::eval
