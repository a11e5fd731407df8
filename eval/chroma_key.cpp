#include "eval/chroma_key.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace rigc::eval {

namespace fs = std::filesystem;

namespace {

// sRGB code -> linear value.
const std::array<float, 256>& linear_of_code() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      t[i] = static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    return t;
  }();
  return table;
}

ir::Vec3 linear_pixel(const std::vector<std::uint8_t>& srgb, std::size_t i) {
  const auto& lin = linear_of_code();
  return {lin[srgb[3 * i]], lin[srgb[3 * i + 1]], lin[srgb[3 * i + 2]]};
}

// Below this sum of linear R, G and B the chromaticity is mostly JPEG noise.
constexpr double kDarkestKeyed = 0.01;

// How far from the median backdrop at the borders a pixel seen through the object may be: a
// stop (velvet's folds and the lens's flare lift it; a shaded face is further), plus the
// sensor's noise floor in linear luminance.
constexpr double kBackdropLevelStops = 1;
constexpr double kBackdropNoise = 0.002;

}  // namespace

bool read_uint8_image(const fs::path& path, OIIO::ImageBuf& image, std::string* error) {
  // Through ImageInput, not ImageBuf's shared cache: a file rewritten under the same name
  // (a mask redone, a photo replaced) is read again.
  auto input = OIIO::ImageInput::open(path.string());
  if (!input) {
    *error = fmt::format("cannot read the pixels of {}: {}", path.string(), OIIO::geterror());
    return false;
  }
  OIIO::ImageSpec spec = input->spec();
  spec.set_format(OIIO::TypeDesc::UINT8);
  image.reset(spec);
  if (!input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, image.localpixels())) {
    *error = fmt::format("cannot read the pixels of {}: {}", path.string(), input->geterror());
    return false;
  }
  return true;
}

std::optional<KeyImage> read_key_image(const fs::path& path, int max_side, std::string* error) {
  OIIO::ImageBuf in;
  if (!read_uint8_image(path, in, error)) return std::nullopt;
  const OIIO::ImageSpec& spec = in.spec();
  const int long_side = std::max(spec.width, spec.height);
  OIIO::ImageBuf work = in;
  if (long_side > max_side) {
    const double s = static_cast<double>(max_side) / long_side;
    const int w = std::max(1, static_cast<int>(std::lround(spec.width * s)));
    const int h = std::max(1, static_cast<int>(std::lround(spec.height * s)));
    work = OIIO::ImageBufAlgo::resize(in, "", 0, OIIO::ROI(0, w, 0, h, 0, 1, 0, spec.nchannels));
  }
  KeyImage image;
  image.width = work.spec().width;
  image.height = work.spec().height;
  image.srgb.resize(image.pixels() * 3);
  const int channels = work.spec().nchannels;
  std::vector<std::uint8_t> all(image.pixels() * channels);
  if (!work.get_pixels(work.roi(), OIIO::TypeDesc::UINT8, all.data())) {
    *error = fmt::format("cannot read the pixels of {}: {}", path.string(), work.geterror());
    return std::nullopt;
  }
  for (std::size_t i = 0; i < image.pixels(); ++i) {
    for (int c = 0; c < 3; ++c)
      image.srgb[3 * i + c] = all[i * channels + std::min(c, channels - 1)];
  }
  return image;
}

Chroma chroma_of_linear(const ir::Vec3& rgb) {
  const double sum = rgb.sum();
  if (sum <= 0) return {1.0 / 3, 1.0 / 3};
  return {rgb.x() / sum, rgb.y() / sum};
}

double chroma_distance(const Chroma& a, const Chroma& b) {
  return std::hypot(a.r - b.r, a.g - b.g);
}

std::optional<Chroma> backdrop_at_borders(const KeyImage& image, const std::optional<Chroma>& hint,
                                          double tolerance) {
  const int band = std::max(1, std::min(image.width, image.height) / 50);
  std::vector<Chroma> border;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const bool edge = x < band || y < band || x >= image.width - band || y >= image.height - band;
      if (!edge) continue;
      const ir::Vec3 rgb = linear_pixel(image.srgb, static_cast<std::size_t>(y) * image.width + x);
      if (rgb.sum() < kDarkestKeyed) continue;
      const Chroma c = chroma_of_linear(rgb);
      // Near the scene's colour: a wide margin, since white balance moves it.
      if (hint && chroma_distance(c, *hint) > 3 * tolerance) continue;
      border.push_back(c);
    }
  }
  if (border.empty()) return std::nullopt;
  auto median_of = [&](auto value) {
    std::vector<double> v;
    v.reserve(border.size());
    for (const auto& c : border) v.push_back(value(c));
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  const Chroma key{median_of([](const Chroma& c) { return c.r; }),
                   median_of([](const Chroma& c) { return c.g; })};
  const std::size_t all_border =
      2 * static_cast<std::size_t>(band) * (image.width + image.height - 2 * band);
  const auto near = std::count_if(border.begin(), border.end(), [&](const Chroma& c) {
    return chroma_distance(c, key) <= tolerance;
  });
  if (2 * static_cast<std::size_t>(near) < all_border) return std::nullopt;
  return key;
}

namespace {

// Rec. 709 luminance of a pixel, linear.
double luminance_of(const KeyImage& image, std::size_t i) {
  const ir::Vec3 rgb = linear_pixel(image.srgb, i);
  return 0.2126 * rgb.x() + 0.7152 * rgb.y() + 0.0722 * rgb.z();
}

// Otsu's threshold over 256 bins of `values` in [0, 1]: the bin edge with the largest variance
// between the two classes.
double otsu_threshold(const std::vector<double>& values) {
  constexpr int kBins = 256;
  std::vector<double> histogram(kBins, 0);
  for (double v : values) histogram[std::clamp(static_cast<int>(v * kBins), 0, kBins - 1)] += 1;
  double total = 0, weighted = 0;
  for (int b = 0; b < kBins; ++b) {
    total += histogram[b];
    weighted += b * histogram[b];
  }
  double below = 0, below_weighted = 0, best = -1;
  int best_bin = kBins / 2;
  for (int b = 0; b < kBins - 1; ++b) {
    below += histogram[b];
    below_weighted += b * histogram[b];
    const double above = total - below;
    if (below == 0 || above == 0) continue;
    const double mean_below = below_weighted / below;
    const double mean_above = (weighted - below_weighted) / above;
    const double between = below * above * (mean_below - mean_above) * (mean_below - mean_above);
    if (between > best) {
      best = between;
      best_bin = b;
    }
  }
  return (best_bin + 1.0) / kBins;
}

// The luminance of the pixels in a band at the image's borders, a fiftieth of its shorter side.
std::vector<double> border_luminances(const KeyImage& image) {
  const int band = std::max(1, std::min(image.width, image.height) / 50);
  std::vector<double> border;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (!(x < band || y < band || x >= image.width - band || y >= image.height - band)) continue;
      border.push_back(luminance_of(image, static_cast<std::size_t>(y) * image.width + x));
    }
  }
  return border;
}

}  // namespace

std::optional<BrightBackdrop> backdrop_brightness_at_borders(const KeyImage& image) {
  const std::vector<double> luminances = border_luminances(image);
  const std::size_t border = luminances.size();
  const auto dark = static_cast<std::size_t>(
      std::count_if(luminances.begin(), luminances.end(), [](double l) { return l < 0.05; }));
  const auto bright = static_cast<std::size_t>(
      std::count_if(luminances.begin(), luminances.end(), [](double l) { return l > 0.8; }));
  if (border == 0) return std::nullopt;
  if (10 * dark >= 9 * border) return BrightBackdrop::kDark;
  if (10 * bright >= 9 * border) return BrightBackdrop::kBright;
  return std::nullopt;
}

std::vector<std::uint8_t> key_brightness(const KeyImage& image, BrightBackdrop backdrop) {
  // Otsu on the square root of luminance: a lit object against black velvet spans the brighter
  // half of a perceptual scale, which splits better than the linear one.
  std::vector<double> lightness(image.pixels());
  for (std::size_t i = 0; i < image.pixels(); ++i) {
    lightness[i] = std::sqrt(std::max(0.0, luminance_of(image, i)));
  }
  // A fifth of the way from Otsu's threshold towards the backdrop: a shaded face of the object
  // is darker than the lit ones that set the threshold, and a mask that cuts it out carves a
  // hull; further, the velvet's folds join the object.
  const double otsu = otsu_threshold(lightness);
  const double threshold = backdrop == BrightBackdrop::kDark ? 0.8 * otsu : otsu + 0.2 * (1 - otsu);
  std::vector<std::uint8_t> mask(image.pixels(), 0);
  for (std::size_t i = 0; i < image.pixels(); ++i) {
    const bool object =
        backdrop == BrightBackdrop::kDark ? lightness[i] >= threshold : lightness[i] < threshold;
    mask[i] = object ? 255 : 0;
  }
  return mask;
}

std::vector<std::uint8_t> at_backdrop_level(const KeyImage& image, BrightBackdrop backdrop) {
  std::vector<double> border = border_luminances(image);
  std::vector<std::uint8_t> level(image.pixels(), 0);
  if (border.empty()) return level;
  const auto median = border.begin() + static_cast<std::ptrdiff_t>(border.size() / 2);
  std::nth_element(border.begin(), median, border.end());
  const bool dark = backdrop == BrightBackdrop::kDark;
  const double stops = std::exp2(kBackdropLevelStops);
  const double limit = dark ? *median * stops + kBackdropNoise : *median / stops;
  for (std::size_t i = 0; i < image.pixels(); ++i) {
    const double l = luminance_of(image, i);
    level[i] = (dark ? l <= limit : l >= limit) ? 255 : 0;
  }
  return level;
}

std::vector<std::uint8_t> key_backdrop(const KeyImage& image, const Chroma& key, double tolerance) {
  std::vector<std::uint8_t> mask(image.pixels(), 255);
  for (std::size_t i = 0; i < image.pixels(); ++i) {
    const ir::Vec3 rgb = linear_pixel(image.srgb, i);
    if (rgb.sum() < kDarkestKeyed) continue;
    if (chroma_distance(chroma_of_linear(rgb), key) <= tolerance) mask[i] = 0;
  }
  return mask;
}

namespace {

// Whether two linear colours are one surface under the same light: within JPEG's noise and a
// tenth of their brightness, channel by channel.
bool same_colour(const ir::Vec3& a, const ir::Vec3& b) {
  for (int c = 0; c < 3; ++c) {
    if (std::abs(a[c] - b[c]) > 0.01 + 0.1 * std::max(a[c], b[c])) return false;
  }
  return true;
}

// Whether `pixel` is `background` in a shadow: darker, the same chromaticity.
bool shadow_of(const ir::Vec3& pixel, const ir::Vec3& background) {
  const double ratio = pixel.sum() / std::max(1e-6, background.sum());
  if (ratio < 0.15 || ratio > 1.0) return false;
  return chroma_distance(chroma_of_linear(pixel), chroma_of_linear(background)) < 0.04;
}

}  // namespace

// The share of the photos that must agree on a pixel's colour for it to be still: a turning
// object's softly textured surface matches its own median in about half of them.
constexpr float kStillShare = 0.8f;

std::optional<StillBackground> still_background(const std::vector<const KeyImage*>& images) {
  constexpr std::size_t kFewest = 5;
  if (images.size() < kFewest) return std::nullopt;
  const KeyImage& first = *images.front();
  for (const KeyImage* im : images) {
    if (im->width != first.width || im->height != first.height) return std::nullopt;
  }
  StillBackground still;
  still.width = first.width;
  still.height = first.height;
  const std::size_t n = first.pixels();
  still.median_srgb.resize(3 * n);
  still.still_share.resize(n);
  std::vector<std::uint8_t> values(images.size());
  for (std::size_t v = 0; v < 3 * n; ++v) {
    for (std::size_t k = 0; k < images.size(); ++k) values[k] = images[k]->srgb[v];
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    still.median_srgb[v] = values[values.size() / 2];
  }
  std::size_t still_pixels = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const ir::Vec3 median = linear_pixel(still.median_srgb, i);
    int agree = 0;
    for (const KeyImage* im : images) agree += same_colour(linear_pixel(im->srgb, i), median);
    still.still_share[i] = static_cast<float>(agree) / static_cast<float>(images.size());
    still_pixels += still.still_share[i] >= kStillShare;
  }
  still.still_fraction = static_cast<double>(still_pixels) / static_cast<double>(n);
  return still;
}

std::vector<std::uint8_t> key_still(const KeyImage& image, const StillBackground& still) {
  std::vector<std::uint8_t> mask(image.pixels(), 255);
  if (image.width != still.width || image.height != still.height) return mask;
  for (std::size_t i = 0; i < image.pixels(); ++i) {
    if (still.still_share[i] < kStillShare) continue;
    const ir::Vec3 pixel = linear_pixel(image.srgb, i);
    const ir::Vec3 background = linear_pixel(still.median_srgb, i);
    if (same_colour(pixel, background) || shadow_of(pixel, background)) mask[i] = 0;
  }
  return mask;
}

namespace {

// Square max filter of radius r (a dilation of the 255 pixels), separable.
std::vector<std::uint8_t> dilate(const std::vector<std::uint8_t>& in, int w, int h, int r) {
  if (r <= 0) return in;
  std::vector<std::uint8_t> rows(in.size()), out(in.size());
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      std::uint8_t m = 0;
      for (int dx = std::max(0, x - r); dx <= std::min(w - 1, x + r); ++dx) {
        m = std::max(m, in[static_cast<std::size_t>(y) * w + dx]);
      }
      rows[static_cast<std::size_t>(y) * w + x] = m;
    }
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      std::uint8_t m = 0;
      for (int dy = std::max(0, y - r); dy <= std::min(h - 1, y + r); ++dy) {
        m = std::max(m, rows[static_cast<std::size_t>(dy) * w + x]);
      }
      out[static_cast<std::size_t>(y) * w + x] = m;
    }
  }
  return out;
}

std::vector<std::uint8_t> inverted(std::vector<std::uint8_t> mask) {
  for (auto& v : mask) v = 255 - v;
  return mask;
}

std::vector<std::uint8_t> erode(const std::vector<std::uint8_t>& in, int w, int h, int r) {
  return inverted(dilate(inverted(in), w, h, r));
}

// Labels the 4-connected regions of pixels equal to `value`; returns each region's size, label
// k in labels (k + 1; 0 for the other pixels).
std::vector<std::size_t> label_regions(const std::vector<std::uint8_t>& mask, int w, int h,
                                       std::uint8_t value, std::vector<int>& labels) {
  labels.assign(mask.size(), 0);
  std::vector<std::size_t> sizes, stack;
  for (std::size_t start = 0; start < mask.size(); ++start) {
    if (mask[start] != value || labels[start]) continue;
    sizes.push_back(0);
    const int label = static_cast<int>(sizes.size());
    stack.push_back(start);
    labels[start] = label;
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      ++sizes.back();
      const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
      const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
      for (int k = 0; k < 4; ++k) {
        if (nx[k] < 0 || ny[k] < 0 || nx[k] >= w || ny[k] >= h) continue;
        const std::size_t j = static_cast<std::size_t>(ny[k]) * w + nx[k];
        if (mask[j] == value && !labels[j]) {
          labels[j] = label;
          stack.push_back(j);
        }
      }
    }
  }
  return sizes;
}

// Keeps the components of at least a tenth of the largest one's size.
void keep_large_components(std::vector<std::uint8_t>& mask, int w, int h) {
  std::vector<int> labels;
  const auto sizes = label_regions(mask, w, h, 255, labels);
  if (sizes.empty()) return;
  const std::size_t largest = *std::max_element(sizes.begin(), sizes.end());
  for (std::size_t i = 0; i < mask.size(); ++i) {
    if (labels[i] && 10 * sizes[labels[i] - 1] < largest) mask[i] = 0;
  }
}

// Fills the background regions that do not reach the image's border and are smaller than
// `least_kept` pixels.
void fill_holes(std::vector<std::uint8_t>& mask, int w, int h, double least_kept) {
  std::vector<int> labels;
  const auto sizes = label_regions(mask, w, h, 0, labels);
  std::vector<bool> reaches_border(sizes.size(), false);
  for (int x = 0; x < w; ++x) {
    for (int y : {0, h - 1}) {
      if (const int l = labels[static_cast<std::size_t>(y) * w + x]) reaches_border[l - 1] = true;
    }
  }
  for (int y = 0; y < h; ++y) {
    for (int x : {0, w - 1}) {
      if (const int l = labels[static_cast<std::size_t>(y) * w + x]) reaches_border[l - 1] = true;
    }
  }
  for (std::size_t i = 0; i < mask.size(); ++i) {
    const int l = labels[i];
    if (!l || reaches_border[l - 1]) continue;
    if (static_cast<double>(sizes[l - 1]) < least_kept) mask[i] = 255;
  }
}

// The share of the object's area from which a hole is the backdrop seen through the object
// (between a temple's columns, through a handle), which a visual hull must carve and features
// must avoid: keying noise, highlights and specks of the object's own colour are smaller.
constexpr double kSeeThroughShare = 0.01;

// Fills the holes in `mask` but for the gaps the backdrop shows through: first every hole pixel
// `see_through` does not mark (when given), then the holes left smaller than kSeeThroughShare.
void fill_all_but_see_through(std::vector<std::uint8_t>& mask, int w, int h,
                              const std::vector<std::uint8_t>* see_through) {
  const auto object = static_cast<double>(std::count(mask.begin(), mask.end(), 255));
  if (see_through && see_through->size() == mask.size()) {
    std::vector<std::uint8_t> filled = mask;
    fill_holes(filled, w, h, std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < mask.size(); ++i) {
      if (filled[i] && !mask[i] && !(*see_through)[i]) mask[i] = 255;
    }
  }
  fill_holes(mask, w, h, kSeeThroughShare * object);
}

}  // namespace

void drop_border_components(std::vector<std::uint8_t>& mask, int w, int h) {
  std::vector<int> labels;
  const auto sizes = label_regions(mask, w, h, 255, labels);
  std::vector<bool> reaches_border(sizes.size(), false);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (x != 0 && y != 0 && x != w - 1 && y != h - 1) continue;
      if (const int l = labels[static_cast<std::size_t>(y) * w + x]) reaches_border[l - 1] = true;
    }
  }
  for (std::size_t i = 0; i < mask.size(); ++i) {
    if (labels[i] && reaches_border[labels[i] - 1]) mask[i] = 0;
  }
}

std::vector<std::uint8_t> clean_object_mask(std::vector<std::uint8_t> mask, int w, int h,
                                            int grow_px,
                                            const std::vector<std::uint8_t>* see_through) {
  constexpr int kSpeck = 1;  // an opening of this radius removes noise and thin spill fringes
  mask = dilate(erode(mask, w, h, kSpeck), w, h, kSpeck);
  keep_large_components(mask, w, h);
  fill_all_but_see_through(mask, w, h, see_through);
  return dilate(mask, w, h, grow_px);
}

std::vector<std::uint8_t> scale_mask(const std::vector<std::uint8_t>& mask, int w, int h, int to_w,
                                     int to_h) {
  if (w == to_w && h == to_h) return mask;
  std::vector<std::uint8_t> out(static_cast<std::size_t>(to_w) * to_h);
  for (int y = 0; y < to_h; ++y) {
    const int sy = std::min(h - 1, static_cast<int>((y + 0.5) * h / to_h));
    for (int x = 0; x < to_w; ++x) {
      const int sx = std::min(w - 1, static_cast<int>((x + 0.5) * w / to_w));
      out[static_cast<std::size_t>(y) * to_w + x] = mask[static_cast<std::size_t>(sy) * w + sx];
    }
  }
  return out;
}

}  // namespace rigc::eval
