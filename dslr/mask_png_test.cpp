#include "dslr/mask_png.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <cstring>
#include <fstream>
#include <random>
#include <vector>

#include "tests/test_support.h"

namespace rigc::dslr {
namespace {

std::uint32_t big_endian_at(const std::string& bytes, std::size_t at) {
  std::uint32_t value = 0;
  for (int k = 0; k < 4; ++k) value = value << 8 | static_cast<std::uint8_t>(bytes[at + k]);
  return value;
}

// The zlib stream of the file's IDAT chunks, inflated by zlib itself (which checks the
// stream's Adler-32), as the filtered rows: a filter byte, then the row.
std::vector<std::uint8_t> inflated_rows(const std::string& png, std::size_t expected_size) {
  std::string stream;
  for (std::size_t at = 8; at + 12 <= png.size();) {
    const std::uint32_t length = big_endian_at(png, at);
    const std::string type = png.substr(at + 4, 4);
    if (type == "IDAT") stream += png.substr(at + 8, length);
    // Every chunk's CRC covers its type and data.
    const auto* crc_from = reinterpret_cast<const Bytef*>(png.data() + at + 4);
    EXPECT_EQ(crc32(crc32(0L, Z_NULL, 0), crc_from, length + 4),
              big_endian_at(png, at + 8 + length))
        << type;
    at += 12 + length;
  }
  std::vector<std::uint8_t> rows(expected_size + 16);
  uLongf size = rows.size();
  const int status =
      uncompress(rows.data(), &size, reinterpret_cast<const Bytef*>(stream.data()), stream.size());
  EXPECT_EQ(status, Z_OK);
  rows.resize(size);
  return rows;
}

std::vector<std::uint8_t> decoded_by_oiio(const std::string& png, int width, int height) {
  rigc::testing::TempDir dir;
  const std::string path = dir.file("mask.png");
  std::ofstream(path, std::ios::binary) << png;
  auto in = OIIO::ImageInput::open(path);
  EXPECT_TRUE(in) << OIIO::geterror();
  if (!in) return {};
  EXPECT_EQ(in->spec().width, width);
  EXPECT_EQ(in->spec().height, height);
  EXPECT_EQ(in->spec().nchannels, 1);
  EXPECT_EQ(in->spec().format, OIIO::TypeDesc::UINT8);
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(width) * height);
  EXPECT_TRUE(in->read_image(0, 0, 0, 1, OIIO::TypeDesc::UINT8, pixels.data()));
  return pixels;
}

void expect_round_trip(const std::vector<std::uint8_t>& mask, int width, int height) {
  const std::string png = encode_mask_png(view_of(mask, width, height, 1));
  std::vector<std::uint8_t> filtered;
  for (int y = 0; y < height; ++y) {
    filtered.push_back(0);
    filtered.insert(filtered.end(), mask.begin() + static_cast<std::ptrdiff_t>(y) * width,
                    mask.begin() + static_cast<std::ptrdiff_t>(y + 1) * width);
  }
  EXPECT_EQ(inflated_rows(png, filtered.size()), filtered);
  EXPECT_EQ(decoded_by_oiio(png, width, height), mask);
}

TEST(MaskPng, RunsOfEveryLengthAroundTheMatchLimitsDecodeExactly) {
  // Runs of 1 to 3 (below deflate's shortest match), 258 (its longest) and next to its
  // multiples, in a row long enough to hold several, and values besides 0 and 255.
  std::vector<std::uint8_t> mask;
  const int width = 1500, height = 12;
  const int lengths[] = {1, 2, 3, 4, 5, 257, 258, 259, 260, 261, 262, 515, 516, 517, 518, 777};
  std::uint8_t value = 0;
  int k = 0;
  while (mask.size() < static_cast<std::size_t>(width) * height) {
    value = value == 255 ? 0 : (k % 5 == 4 ? 17 : 255);
    mask.insert(mask.end(), lengths[k++ % std::size(lengths)], value);
  }
  mask.resize(static_cast<std::size_t>(width) * height);
  expect_round_trip(mask, width, height);
}

TEST(MaskPng, RandomMasksAndOddShapesDecodeExactly) {
  std::mt19937 random(7);
  for (const auto& [width, height] :
       {std::pair{1, 1}, {1, 300}, {300, 1}, {7, 9}, {8, 8}, {9, 7}, {333, 211}}) {
    // Runs with a geometric length (mean 40) of random bytes from a small set.
    std::vector<std::uint8_t> mask(static_cast<std::size_t>(width) * height);
    std::geometric_distribution<int> run(1.0 / 40);
    const std::uint8_t values[] = {0, 255, 1, 128};
    for (std::size_t at = 0; at < mask.size();) {
      const std::size_t end = std::min(mask.size(), at + 1 + run(random));
      std::fill(mask.begin() + at, mask.begin() + end, values[random() % 4]);
      at = end;
    }
    SCOPED_TRACE(::testing::Message() << width << " x " << height);
    expect_round_trip(mask, width, height);
  }
  // Uniform masks: one run through every row and filter byte.
  for (std::uint8_t value : {0, 255}) {
    expect_round_trip(std::vector<std::uint8_t>(640 * 480, value), 640, 480);
  }
}

TEST(MaskPng, AnObjectMaskPacksAboutAsTightAsZlib) {
  // A disc on a 2000 x 1500 frame: the file must stay within twice zlib's fastest level on the
  // same filtered rows.
  const int width = 2000, height = 1500;
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(width) * height);
  std::vector<std::uint8_t> filtered;
  for (int y = 0; y < height; ++y) {
    filtered.push_back(0);
    for (int x = 0; x < width; ++x) {
      const double dx = x - 1000.5, dy = y - 700.5;
      mask[static_cast<std::size_t>(y) * width + x] = dx * dx + dy * dy < 500.0 * 500.0 ? 255 : 0;
      filtered.push_back(mask[static_cast<std::size_t>(y) * width + x]);
    }
  }
  const std::string png = encode_mask_png(view_of(mask, width, height, 1));
  std::vector<Bytef> packed(compressBound(filtered.size()));
  uLongf packed_size = packed.size();
  ASSERT_EQ(compress2(packed.data(), &packed_size, filtered.data(), filtered.size(), 1), Z_OK);
  EXPECT_LT(png.size(), 2 * packed_size + 100) << "zlib level 1: " << packed_size;
  EXPECT_EQ(decoded_by_oiio(png, width, height), mask);
}

}  // namespace
}  // namespace rigc::dslr
