// A developed frame as the page shows it: a JPEG in memory, and the histogram under it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dslr/image_view.h"

namespace rigc::studio {

// 8-bit RGB as a baseline JPEG of `quality` (1..100); empty on failure (an empty view, too) with
// `error` set.
std::string encode_jpeg(dslr::ImageView<const std::uint8_t> rgb, int quality, std::string* error);

// An image file (any format OpenImageIO reads) as a JPEG of `quality`, with its size; empty on
// failure with `error` set.
std::string jpeg_of_image_file(const std::string& path, int quality, int* width, int* height,
                               std::string* error);

struct Histogram {
  static constexpr int kBins = 64;
  std::vector<int> bins;  // 4 x kBins: red, green, blue, then luma (Rec. 709 weights on codes)
  double clipped = 0;     // share of pixels with some channel at 255
  double mean_luma = 0;   // of the codes, 0..255
};

Histogram histogram_of(const std::vector<std::uint8_t>& rgb);

}  // namespace rigc::studio
