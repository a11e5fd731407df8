#include "eval/photos.h"

#include <fmt/format.h>

namespace rigc::eval {

std::optional<PhotoSetup> prepare_photos(const EvalOptions& o, const EvalInputs& in,
                                         std::ostream& log, std::string* error) {
  PhotoSetup setup;
  auto cameras = photo_cameras(in.images, o.camera, error);
  if (!cameras) return std::nullopt;
  setup.cameras = std::move(*cameras);
  if (!o.quiet) {
    for (const auto& c : setup.cameras) {
      log << fmt::format("rigc eval: camera {} for {} photo(s): {}{}\n", c.label, c.images.size(),
                         c.source,
                         c.focal_px > 0 ? fmt::format(", f = {:.1f} px", c.focal_px) : "");
    }
  }
  setup.order = capture_order(in.images, &setup.order_basis);
  if (o.use_masks || !o.masks_dir.empty()) {
    PhotoMaskOptions mask_options;
    mask_options.masks_dir = o.masks_dir;
    mask_options.backdrop_color = in.truth.backdrop_color;
    mask_options.tolerance = o.key_tolerance;
    mask_options.quiet = o.quiet;
    auto masks = make_photo_masks(in.images, mask_options, in.out, log, error);
    if (!masks) return std::nullopt;
    setup.masks = std::move(*masks);
  }
  return setup;
}

}  // namespace rigc::eval
