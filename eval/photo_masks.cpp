#include "eval/photo_masks.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <fmt/format.h>

#include <algorithm>
#include <map>

#include "dslr/image_io.h"
#include "eval/chroma_key.h"
#include "io/input_files.h"
#include "io/output_paths.h"

namespace rigc::eval {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Keying works on pictures this size at most: the silhouette needs no more.
constexpr int kKeySide = 1024;

// A mask that keeps almost nothing or almost everything is no mask: the key found no object.
bool plausible_coverage(double coverage) {
  return coverage > 0.002 && coverage < 0.97;
}

double coverage_of(const std::vector<std::uint8_t>& mask) {
  if (mask.empty()) return 0;
  return static_cast<double>(std::count(mask.begin(), mask.end(), 255)) /
         static_cast<double>(mask.size());
}

bool write_full_size_mask(const fs::path& path, const std::vector<std::uint8_t>& mask, int w, int h,
                          std::pair<int, int> full, std::string* error) {
  const std::vector<std::uint8_t> scaled = scale_mask(mask, w, h, full.first, full.second);
  return dslr::write_mask(path, dslr::view_of(scaled, full.first, full.second, 1), error);
}

// The still background of each working size that at least five photos share.
std::map<std::pair<int, int>, StillBackground> still_backgrounds(
    const std::vector<std::optional<KeyImage>>& pictures) {
  std::map<std::pair<int, int>, std::vector<const KeyImage*>> by_size;
  for (const auto& p : pictures) {
    if (p) by_size[{p->width, p->height}].push_back(&*p);
  }
  std::map<std::pair<int, int>, StillBackground> still;
  for (const auto& [size, group] : by_size) {
    if (auto s = still_background(group)) still[size] = std::move(*s);
  }
  return still;
}

// One photo's keyed mask (empty when no key applies), and its line of the report.
std::vector<std::uint8_t> key_one(const KeyImage& picture, const std::optional<Chroma>& hint,
                                  const StillBackground* still, const PhotoMaskOptions& o,
                                  json& entry) {
  const double tolerance = o.tolerance;
  // Black velvet or a light tent: keyed by brightness (a green screen is neither).
  if (const auto brightness = hint ? std::nullopt : backdrop_brightness_at_borders(picture)) {
    entry["backdrop"] = *brightness == BrightBackdrop::kDark ? "dark" : "bright";
    std::vector<std::uint8_t> mask = key_brightness(picture, *brightness);
    drop_border_components(mask, picture.width, picture.height);
    const std::vector<std::uint8_t> see_through = at_backdrop_level(picture, *brightness);
    return clean_object_mask(std::move(mask), picture.width, picture.height, o.grow_px,
                             &see_through);
  }
  const auto key = backdrop_at_borders(picture, hint, tolerance);
  if (!key && !still) return {};
  std::vector<std::uint8_t> mask(picture.pixels(), 255);
  if (key) {
    mask = key_backdrop(picture, *key, tolerance);
    entry["backdrop_chromaticity"] = {key->r, key->g};
  }
  if (still) {
    const auto moving = key_still(picture, *still);
    for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = std::min(mask[i], moving[i]);
  }
  entry["still_background"] = still != nullptr;
  return clean_object_mask(std::move(mask), picture.width, picture.height, o.grow_px);
}

bool key_masks(const ImageSet& images, const PhotoMaskOptions& o, const fs::path& dir, json& report,
               std::string* error) {
  // A photo whose pixels cannot be read gets no mask; the COLMAP stage names it.
  std::vector<std::optional<KeyImage>> pictures;
  std::vector<std::string> unreadable(images.names.size());
  for (std::size_t k = 0; k < images.names.size(); ++k) {
    pictures.push_back(read_key_image(images.dir / images.names[k], kKeySide, &unreadable[k]));
  }
  std::optional<Chroma> hint;
  if (o.backdrop_color) hint = chroma_of_linear(*o.backdrop_color);
  const auto still = still_backgrounds(pictures);
  report["method"] =
      hint ? "chroma key on the scene's green screen, and the still background"
           : "chroma key on the colour at the borders, and the still background (a brightness "
             "key where the borders are black or white)";
  report["tolerance"] = o.tolerance;
  json& by_photo = report["photos"];
  for (std::size_t k = 0; k < pictures.size(); ++k) {
    if (!pictures[k]) {
      by_photo[images.names[k]] = {{"mask", nullptr}, {"why_none", unreadable[k]}};
      continue;
    }
    const KeyImage& p = *pictures[k];
    const auto s = still.find({p.width, p.height});
    if (s != still.end()) report["still_fraction"] = s->second.still_fraction;
    json entry;
    const auto mask = key_one(p, hint, s == still.end() ? nullptr : &s->second, o, entry);
    const double coverage = coverage_of(mask);
    entry["coverage"] = coverage;
    if (!plausible_coverage(coverage)) {
      entry["mask"] = nullptr;
      entry["why_none"] = mask.empty() ? "no backdrop colour at the borders and nothing still"
                                       : "the key kept almost nothing or almost everything";
    } else {
      const fs::path path = dir / (fs::path(images.names[k]).stem().string() + ".png");
      if (!write_full_size_mask(path, mask, p.width, p.height, images.size.at(images.names[k]),
                                error)) {
        return false;
      }
      entry["mask"] = path.string();
    }
    by_photo[images.names[k]] = entry;
  }
  return true;
}

// The file of the mask made elsewhere for `name`: the same stem, any common image format, or
// COLMAP's own convention (the full name + ".png").
std::optional<fs::path> mask_file_for(const fs::path& masks_dir, const std::string& name) {
  const std::string stem = fs::path(name).stem().string();
  for (const char* ext : {".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".pgm", ".webp"}) {
    for (const std::string& base : {stem, name}) {
      const fs::path p = masks_dir / (base + ext);
      std::error_code ec;
      if (fs::is_regular_file(p, ec)) return p;
    }
  }
  return std::nullopt;
}

// One mask made elsewhere as 0/255 at the photo's size: its alpha channel when it has one, else
// its first channel, thresholded at half.
std::optional<std::vector<std::uint8_t>> read_mask_made_elsewhere(const fs::path& path,
                                                                  std::pair<int, int> size,
                                                                  std::string* error) {
  OIIO::ImageBuf in;
  if (!read_uint8_image(path, in, error)) return std::nullopt;
  const OIIO::ImageSpec& spec = in.spec();
  if (spec.width != size.first || spec.height != size.second) {
    *error = fmt::format("the mask {} is {}x{} pixels, its photo {}x{}", path.string(), spec.width,
                         spec.height, size.first, size.second);
    return std::nullopt;
  }
  const int channel = spec.alpha_channel >= 0 ? spec.alpha_channel : 0;
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(spec.width) * spec.height);
  in.get_pixels(OIIO::ROI(0, spec.width, 0, spec.height, 0, 1, channel, channel + 1),
                OIIO::TypeDesc::UINT8, mask.data());
  for (auto& v : mask) v = v >= 128 ? 255 : 0;
  return mask;
}

bool import_masks(const ImageSet& images, const PhotoMaskOptions& o, const fs::path& dir,
                  json& report, std::string* error) {
  report["method"] = fmt::format("masks made elsewhere ({})", o.masks_dir);
  json& by_photo = report["photos"];
  int found = 0;
  for (const auto& name : images.names) {
    const auto file = mask_file_for(o.masks_dir, name);
    if (!file) {
      by_photo[name] = {{"mask", nullptr}, {"why_none", "no mask of this name in --masks"}};
      continue;
    }
    const auto size = images.size.at(name);
    const auto mask = read_mask_made_elsewhere(*file, size, error);
    if (!mask) return false;
    const fs::path path = dir / (fs::path(name).stem().string() + ".png");
    if (!dslr::write_mask(path, dslr::view_of(*mask, size.first, size.second, 1), error))
      return false;
    by_photo[name] = {
        {"mask", path.string()}, {"from", file->string()}, {"coverage", coverage_of(*mask)}};
    ++found;
  }
  if (found == 0) {
    *error = fmt::format(
        "--masks {} has no mask for any of the photos (looked for <photo stem>.png, .jpg, .tif, "
        "... beside each photo's name)",
        o.masks_dir);
    return false;
  }
  return true;
}

}  // namespace

std::optional<PhotoMasks> make_photo_masks(const ImageSet& images, const PhotoMaskOptions& o,
                                           const fs::path& out, std::ostream& log,
                                           std::string* error) {
  PhotoMasks result;
  const fs::path dir = out / "masks";
  if (!o.masks_dir.empty()) protect_input_folder(o.masks_dir, "the masks given by --masks");
  if (!clear_output_folder(dir, error)) return std::nullopt;
  const bool ok = o.masks_dir.empty() ? key_masks(images, o, dir, result.report, error)
                                      : import_masks(images, o, dir, result.report, error);
  if (!ok) return std::nullopt;
  int masked = 0;
  for (const auto& [name, entry] : result.report["photos"].items()) {
    masked += entry.contains("mask") && entry["mask"].is_string();
  }
  result.report["masked_photos"] = masked;
  if (masked == 0) return result;
  result.dir = dir;
  const fs::path sheet = out / "masks_contact_sheet.png";
  std::string why;
  if (write_contact_sheet(images, dir, sheet, &why)) {
    result.contact_sheet = sheet.string();
    result.report["contact_sheet"] = result.contact_sheet;
  } else {
    log << "rigc eval: warning: " << why << "\n";
  }
  if (!o.quiet) {
    log << fmt::format("rigc eval: masks for {} of {} photos ({}) in {}\n", masked,
                       images.names.size(), result.report["method"].get<std::string>(),
                       dir.string());
  }
  return result;
}

namespace {

// The thumbnail of a photo (long side `side`) beside the same with its masked-out pixels tinted.
std::optional<std::pair<OIIO::ImageBuf, OIIO::ImageBuf>> contact_pair(const fs::path& photo,
                                                                      const fs::path& mask_path,
                                                                      int side) {
  std::string error;
  auto picture = read_key_image(photo, side, &error);
  if (!picture) return std::nullopt;
  std::vector<std::uint8_t> mask(picture->pixels(), 255);
  if (fs::exists(mask_path)) {
    auto m = read_key_image(mask_path, side, &error);
    if (m && m->width == picture->width && m->height == picture->height) {
      for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = m->srgb[3 * i] >= 128 ? 255 : 0;
    }
  }
  std::vector<std::uint8_t> tinted = picture->srgb;
  for (std::size_t i = 0; i < mask.size(); ++i) {
    if (mask[i]) continue;
    const std::uint8_t magenta[3] = {200, 0, 200};
    for (int c = 0; c < 3; ++c) tinted[3 * i + c] = (tinted[3 * i + c] + 3 * magenta[c]) / 4;
  }
  const OIIO::ImageSpec spec(picture->width, picture->height, 3, OIIO::TypeDesc::UINT8);
  OIIO::ImageBuf left(spec), right(spec);
  left.set_pixels(left.roi(), OIIO::TypeDesc::UINT8, picture->srgb.data());
  right.set_pixels(right.roi(), OIIO::TypeDesc::UINT8, tinted.data());
  return std::pair{std::move(left), std::move(right)};
}

}  // namespace

bool write_contact_sheet(const ImageSet& images, const fs::path& masks_dir, const fs::path& path,
                         std::string* error) {
  constexpr int kSide = 240, kGap = 6, kPairsPerRow = 3;
  constexpr std::size_t kMostPhotos = 120;
  const std::size_t n = std::min(kMostPhotos, images.names.size());
  const auto [w0, h0] = images.size.at(images.names.front());
  const int cell_w = w0 >= h0 ? kSide : kSide * w0 / std::max(1, h0);
  const int cell_h = w0 >= h0 ? kSide * h0 / std::max(1, w0) : kSide;
  const int rows = static_cast<int>((n + kPairsPerRow - 1) / kPairsPerRow);
  const int sheet_w = kPairsPerRow * (2 * cell_w + 3 * kGap);
  const int sheet_h = rows * (cell_h + kGap) + kGap;
  OIIO::ImageBuf sheet(OIIO::ImageSpec(sheet_w, sheet_h, 3, OIIO::TypeDesc::UINT8));
  const float white[3] = {1, 1, 1};
  OIIO::ImageBufAlgo::fill(sheet, white);
  for (std::size_t k = 0; k < n; ++k) {
    const std::string& name = images.names[k];
    const auto pair = contact_pair(images.dir / name,
                                   masks_dir / (fs::path(name).stem().string() + ".png"), kSide);
    if (!pair) continue;
    const int x = static_cast<int>(k % kPairsPerRow) * (2 * cell_w + 3 * kGap) + kGap;
    const int y = static_cast<int>(k / kPairsPerRow) * (cell_h + kGap) + kGap;
    OIIO::ImageBufAlgo::paste(sheet, x, y, 0, 0, pair->first);
    OIIO::ImageBufAlgo::paste(sheet, x + cell_w + kGap, y, 0, 0, pair->second);
  }
  return dslr::write_image_buffer(path, sheet, error);
}

}  // namespace rigc::eval
