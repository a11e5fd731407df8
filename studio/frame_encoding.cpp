#include "studio/frame_encoding.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>

namespace rigc::studio {

std::string encode_jpeg(dslr::ImageView<const std::uint8_t> rgb, int quality, std::string* error) {
  if (rgb.empty() || rgb.channels != 3) {
    *error = "cannot encode the frame: it is empty or not RGB";
    return {};
  }
  std::vector<unsigned char> bytes;
  OIIO::Filesystem::IOVecOutput proxy(bytes);
  auto out = OIIO::ImageOutput::create("frame.jpg");
  if (!out) {
    *error = "OpenImageIO has no JPEG writer";
    return {};
  }
  OIIO::ImageSpec spec(rgb.width, rgb.height, 3, OIIO::TypeDesc::UINT8);
  spec.attribute("Compression", "jpeg:" + std::to_string(std::clamp(quality, 1, 100)));
  void* proxy_pointer = &proxy;
  spec.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy_pointer);
  if (!out->open("frame.jpg", spec) || !out->write_image(OIIO::TypeDesc::UINT8, rgb.values) ||
      !out->close()) {
    *error = "cannot encode the frame: " + out->geterror();
    return {};
  }
  return std::string(bytes.begin(), bytes.end());
}

std::string jpeg_of_image_file(const std::string& path, int quality, int* width, int* height,
                               std::string* error) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    *error = "cannot read " + path + ": " + OIIO::geterror();
    return {};
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.nchannels < 1 || spec.width < 1 || spec.height < 1) {
    *error = "the image " + path + " has no pixels";
    return {};
  }
  *width = spec.width;
  *height = spec.height;
  const size_t pixels = static_cast<size_t>(spec.width) * spec.height;
  std::vector<std::uint8_t> rgb(pixels * 3);
  const int channels = std::min(spec.nchannels, 3);
  if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, rgb.data(), 3)) {
    *error = "cannot read " + path + ": " + in->geterror();
    return {};
  }
  if (channels == 1) {
    for (size_t i = 0; i < pixels; ++i) rgb[3 * i + 1] = rgb[3 * i + 2] = rgb[3 * i];
  }
  return encode_jpeg(dslr::view_of(rgb, spec.width, spec.height), quality, error);
}

Histogram histogram_of(const std::vector<std::uint8_t>& rgb) {
  Histogram h;
  h.bins.assign(4 * Histogram::kBins, 0);
  const size_t pixels = rgb.size() / 3;
  size_t clipped = 0;
  double luma_sum = 0;
  constexpr int kShift = 2;  // 256 codes into 64 bins
  for (size_t i = 0; i < pixels; ++i) {
    const std::uint8_t r = rgb[3 * i], g = rgb[3 * i + 1], b = rgb[3 * i + 2];
    const double luma = 0.2126 * r + 0.7152 * g + 0.0722 * b;
    ++h.bins[r >> kShift];
    ++h.bins[Histogram::kBins + (g >> kShift)];
    ++h.bins[2 * Histogram::kBins + (b >> kShift)];
    ++h.bins[3 * Histogram::kBins + std::min(63, static_cast<int>(luma) >> kShift)];
    clipped += (r == 255 || g == 255 || b == 255);
    luma_sum += luma;
  }
  if (pixels > 0) {
    h.clipped = static_cast<double>(clipped) / pixels;
    h.mean_luma = luma_sum / pixels;
  }
  return h;
}

}  // namespace rigc::studio
