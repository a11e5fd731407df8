// The checks eval makes on its inputs before COLMAP runs.
#include "eval/inputs.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <sstream>
#include <string>

#include "eval/eval.h"
#include "eval/eval_test_support.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;
using ::testing::Not;

namespace rigc::eval {
namespace {

namespace fs = std::filesystem;
using test_inputs::write_cube_ply;
using test_inputs::write_small_image;

void append_big_endian(std::string& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out += static_cast<char>((v >> shift) & 0xFF);
}

// PNG's CRC-32 (ISO 3309) of a chunk's type and data.
std::uint32_t png_crc(const std::string& bytes) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (const unsigned char byte : bytes) {
    crc ^= byte;
    for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return crc ^ 0xFFFFFFFFu;
}

void append_chunk(std::string& png, const std::string& type_and_data) {
  append_big_endian(png, static_cast<std::uint32_t>(type_and_data.size() - 4));
  png += type_and_data;
  append_big_endian(png, png_crc(type_and_data));
}

// A well-formed PNG claiming width x height RGB pixels whose image data is empty.
std::string png_without_data(std::uint32_t width, std::uint32_t height) {
  std::string header = "IHDR";
  append_big_endian(header, width);
  append_big_endian(header, height);
  header += std::string("\x08\x02\0\0\0", 5);  // 8 bits, RGB, deflate, no filter, no interlace
  std::string png = "\x89PNG\r\n\x1a\n";
  append_chunk(png, header);
  append_chunk(png, "IDAT");
  append_chunk(png, "IEND");
  return png;
}

// Evaluates dir/photos against a cube with a COLMAP that does not exist: the log of the checks
// made before COLMAP would run.
std::string evaluate_photos(const testing::TempDir& dir) {
  write_cube_ply(dir.file("cube.ply"));
  EvalOptions o;
  o.photos_dir = dir.file("photos");
  o.ground_truth = dir.file("cube.ply");
  o.output_dir = dir.file("eval");
  o.sfm.colmap = dir.file("no-such-colmap");
  std::ostringstream log;
  EXPECT_EQ(evaluate(o, log, nullptr), 1);
  EXPECT_FALSE(fs::exists(dir.path() / "eval")) << "nothing is written";
  return log.str();
}

// A header claiming 60000 x 60000 pixels passed the header check, and COLMAP then ran for 30 s,
// took 10.5 GB and aborted.
TEST(EvalInputs, APhotoWhoseHeaderClaimsGigapixelsIsRefused) {
  testing::TempDir dir;
  fs::create_directories(dir.path() / "photos");
  write_small_image(dir.file("photos/b.png"));
  testing::write_text(dir.file("photos/a.png"), png_without_data(60000, 60000));
  const std::string log = evaluate_photos(dir);
  EXPECT_THAT(
      log, HasSubstr("a.png: its header says 60000 x 60000 pixels, more than the 250 megapixels"));
}

// Within the size limit, a header without its pixel data cannot be decoded.
TEST(EvalInputs, APhotoWithoutItsPixelDataCannotBeDecoded) {
  testing::TempDir dir;
  fs::create_directories(dir.path() / "photos");
  write_small_image(dir.file("photos/b.png"));
  write_small_image(dir.file("photos/c.jpg"));
  testing::write_text(dir.file("photos/a.png"), png_without_data(4000, 3000));
  const std::string log = evaluate_photos(dir);
  EXPECT_THAT(log, HasSubstr("1 of the 3 images cannot be read"));
  EXPECT_THAT(log, HasSubstr("a.png: cannot be decoded"));
}

// A JPEG cut short decodes (libjpeg warns and fills grey rows), and passed the check; a PNG
// without its IEND chunk too. Zero bytes after a JPEG's end marker are padding, not damage.
TEST(EvalInputs, APhotoCutShortIsNamed) {
  testing::TempDir dir;
  fs::create_directories(dir.path() / "photos");
  write_small_image(dir.file("photos/a.jpg"));
  write_small_image(dir.file("photos/b.png"));
  write_small_image(dir.file("photos/c.jpg"));
  const std::string jpeg = testing::read_text(dir.file("photos/a.jpg"));
  testing::write_text(dir.file("photos/a.jpg"), jpeg.substr(0, jpeg.size() - 40));
  const std::string png = testing::read_text(dir.file("photos/b.png"));
  testing::write_text(dir.file("photos/b.png"), png.substr(0, png.size() - 12));
  testing::write_text(dir.file("photos/c.jpg"), jpeg + std::string(300, '\0'));
  const std::string log = evaluate_photos(dir);
  EXPECT_THAT(log, HasSubstr("2 of the 3 images cannot be read"));
  EXPECT_THAT(log,
              HasSubstr("a.jpg: is cut short (a JPEG ends with the end-of-image marker FF D9"));
  EXPECT_THAT(log, HasSubstr("b.png: is cut short (a PNG ends with its IEND chunk"));
  EXPECT_THAT(log, Not(HasSubstr("c.jpg")));
}

}  // namespace
}  // namespace rigc::eval
