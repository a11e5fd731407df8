#include "eval/photos.h"

#include <fmt/format.h>

#include <fstream>
#include <sstream>

#include "eval/chroma_key.h"
#include "eval/photo_diagnosis.h"

namespace rigc::eval {

std::optional<PhotoSetup> prepare_photos(const EvalOptions& o, const EvalInputs& in,
                                         std::ostream& log, std::string* error) {
  PhotoSetup setup;
  auto cameras = photo_cameras(in.images, o.photos.camera, error);
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
  if (o.sfm.use_masks || !o.photos.masks_dir.empty()) {
    PhotoMaskOptions mask_options;
    mask_options.masks_dir = o.photos.masks_dir;
    mask_options.backdrop_color = in.truth.backdrop_color;
    mask_options.tolerance = o.photos.key_tolerance;
    mask_options.quiet = o.quiet;
    auto masks = make_photo_masks(in.images, mask_options, in.out, log, error);
    if (!masks) return std::nullopt;
    setup.masks = std::move(*masks);
  }
  return setup;
}

namespace {

namespace fs = std::filesystem;

// Image statistics need no more than this many pixels a side.
constexpr int kStatisticsSide = 768;

// COLMAP's features by image, from every feature_extractor log of OUT/logs.
std::map<std::string, double> colmap_features(const fs::path& logs) {
  std::map<std::string, double> all;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(logs, ec)) {
    if (e.path().filename().string().rfind("feature_extractor", 0) != 0) continue;
    std::ifstream in(e.path());
    std::ostringstream text;
    text << in.rdbuf();
    all.merge(features_by_image(text.str()));
  }
  return all;
}

// The statistics of every image (over its mask when it has one) and the share of still pixels.
void read_statistics(const EvalInputs& in, const PhotoSetup* setup, DiagnosisInputs& d) {
  std::vector<KeyImage> pictures;
  std::string error;
  for (const auto& name : in.images.names) {
    auto picture = read_key_image(in.images.dir / name, kStatisticsSide, &error);
    if (!picture) continue;
    std::vector<std::uint8_t> mask;
    const fs::path mask_path =
        setup && !setup->masks.dir.empty()
            ? setup->masks.dir / (fs::path(name).stem().string() + ".png")
            : in.run_dir / "masks" / (fs::path(name).stem().string() + ".png");
    if (d.masked && fs::exists(mask_path)) {
      if (auto m = read_key_image(mask_path, kStatisticsSide, &error);
          m && m->width == picture->width && m->height == picture->height) {
        mask.resize(m->pixels());
        for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = m->srgb[3 * i];
      }
    }
    d.stats[name] = image_statistics(*picture, mask);
    pictures.push_back(std::move(*picture));
  }
  std::vector<const KeyImage*> all;
  for (const auto& p : pictures) all.push_back(&p);
  if (auto still = still_background(all)) d.still_fraction = still->still_fraction;
}

}  // namespace

nlohmann::json report_unregistered(const EvalInputs& in, const PhotoSetup* setup,
                                   const std::set<std::string>& registered, bool masked,
                                   std::ostream& log) {
  nlohmann::json report = nlohmann::json::object();
  if (registered.size() >= in.images.names.size()) return report;
  DiagnosisInputs d;
  d.order = setup ? setup->order : in.images.names;
  d.registered = registered;
  d.masked = masked;
  d.features = colmap_features(in.out / "logs");
  read_statistics(in, setup, d);
  const auto causes = diagnose_unregistered(d);
  log << fmt::format("rigc eval: {} of {} images did not register:\n",
                     in.images.names.size() - registered.size(), in.images.names.size());
  for (const auto& [name, why] : causes) {
    std::string line;
    for (const auto& c : why) line += (line.empty() ? "" : "; ") + c;
    log << fmt::format("rigc eval:   {}: {}\n", name, line);
    report[name] = why;
  }
  return report;
}

}  // namespace rigc::eval
