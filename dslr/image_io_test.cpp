#include "dslr/image_io.h"

#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>

#include "dslr/dslr_test_support.h"
#include "dslr/pipeline.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc::dslr {
namespace {

namespace fs = std::filesystem;
using testing::canon_6d;
using testing::flat_frame;

DevelopResult small_image(const ir::Camera& camera) {
  LinearFrame frame = flat_frame(sensor_intrinsics(camera, 0.05), 800, 1.0f);
  frame.mask.assign(static_cast<std::size_t>(frame.width) * frame.height, 0);
  for (std::size_t p = 0; p < frame.mask.size(); p += 3) frame.mask[p] = 255;
  return develop_frame(camera, frame, {1, 0, 1}, 0.05);
}

std::vector<std::string> folder_entries(const fs::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder)) names.push_back(entry.path().filename());
  return names;
}

TEST(DslrWrite, JpegCarriesTheExifACameraWouldWrite) {
  rigc::testing::TempDir dir;
  ir::Camera camera = canon_6d();
  camera.iso = 400;
  const DevelopResult image = small_image(camera);
  const std::string path = dir.file("shot_000.jpg");
  std::string error;
  ASSERT_TRUE(write_image(path, image, camera, &error)) << error;
  EXPECT_EQ(folder_entries(dir.path()), std::vector<std::string>{"shot_000.jpg"});

  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in) << OIIO::geterror();
  const OIIO::ImageSpec& spec = in->spec();
  EXPECT_EQ(spec.width, image.width);
  EXPECT_EQ(spec.height, image.height);
  EXPECT_EQ(spec.get_string_attribute("Make"), "Canon");
  EXPECT_EQ(spec.get_string_attribute("Model"), "Canon EOS 6D");
  EXPECT_NEAR(spec.get_float_attribute("Exif:FocalLength"), 50, 1e-3);
  EXPECT_NEAR(spec.get_float_attribute("FNumber"), 8, 1e-3);
  EXPECT_NEAR(spec.get_float_attribute("ExposureTime"), 1.0 / 125, 1e-6);
  const int iso = std::max(spec.get_int_attribute("Exif:PhotographicSensitivity"),
                           spec.get_int_attribute("Exif:ISOSpeedRatings"));
  EXPECT_EQ(iso, 400);
  // Pixels per cm on the focal plane: f_px = f_mm · resolution / 10.
  EXPECT_EQ(spec.get_int_attribute("Exif:FocalPlaneResolutionUnit"), 3);
  const double f_px = 50 * spec.get_float_attribute("Exif:FocalPlaneXResolution") / 10;
  EXPECT_NEAR(f_px, 0.05 * image.width / 0.0358, 0.01);
  EXPECT_EQ(spec.get_int_attribute("Exif:FocalLengthIn35mmFilm"), 50);
  std::vector<std::uint8_t> pixels(image.encoded.size());
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, pixels.data()));
  EXPECT_NEAR(pixels[0], image.encoded[0], 3);  // JPEG at quality 95
}

// EXIF ASCII is 7-bit: a camera named in UTF-8 (or with a control character) is written with '?'
// for each character outside it, read back the same by OpenImageIO and libexif readers.
TEST(DslrWrite, ExifTextIsSevenBitAscii) {
  rigc::testing::TempDir dir;
  ir::Camera camera = canon_6d();
  camera.make = "Caf\xC3\xA9 \xE2\x80\xAE\x01Zw\xC3\xB6lf";
  camera.model = "\xF0\x9F\x93\xB7 EOS";
  const std::string path = dir.file("shot_000.jpg");
  std::string error;
  ASSERT_TRUE(write_image(path, small_image(camera), camera, &error)) << error;
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in) << OIIO::geterror();
  EXPECT_EQ(in->spec().get_string_attribute("Make"), "Caf? ??Zw?lf");
  EXPECT_EQ(in->spec().get_string_attribute("Model"), "? EOS");
}

// A JPEG holds 8-bit codes: an 8-bit result's codes as they are, a 16-bit one's scaled down
// (65535 -> 255). A smooth ramp survives quality 100 within a code or two.
TEST(DslrWrite, JpegPixelsAreTheEightBitCodes) {
  rigc::testing::TempDir dir;
  ir::Camera camera = canon_6d();
  camera.jpeg_quality = 100;
  for (const int bits : {8, 16, 0}) {  // 0: 8-bit codes as bytes (DevelopResult::encoded_bytes)
    DevelopResult image;
    image.width = 64;
    image.height = 16;
    image.bits = bits == 16 ? 16 : 8;
    std::vector<int> expected(3 * 64 * 16);
    for (std::size_t i = 0; i < expected.size(); ++i) {
      const int code = static_cast<int>(40 + 2 * ((i / 3) % 64) + 10 * (i % 3));
      expected[i] = code;
      if (bits == 0) {
        image.encoded_bytes.push_back(static_cast<std::uint8_t>(code));
      } else {
        image.encoded.push_back(static_cast<std::uint16_t>(bits == 8 ? code : code * 256 + 128));
      }
    }
    const std::string path = dir.file("ramp" + std::to_string(bits) + ".jpg");
    std::string error;
    ASSERT_TRUE(write_image(path, image, camera, &error)) << error;
    auto in = OIIO::ImageInput::open(path);
    ASSERT_TRUE(in);
    std::vector<std::uint8_t> pixels(expected.size());
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, pixels.data()));
    int worst = 0;
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      worst = std::max(worst, std::abs(pixels[i] - expected[i]));
    }
    EXPECT_LE(worst, 3) << bits << " bits";
  }
}

TEST(DslrWrite, Png16KeepsEveryCodeValue) {
  rigc::testing::TempDir dir;
  ir::Camera camera = canon_6d();
  camera.format = ir::ImageFormat::kPng16;
  const DevelopResult image = small_image(camera);
  const std::string path = dir.file("shot_000.png");
  std::string error;
  ASSERT_TRUE(write_image(path, image, camera, &error)) << error;
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in);
  std::vector<std::uint16_t> pixels(image.encoded.size());
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT16, pixels.data()));
  EXPECT_EQ(pixels, image.encoded);
}

TEST(DslrWrite, MaskIsAnEightBitPng) {
  rigc::testing::TempDir dir;
  const ir::Camera camera = canon_6d();
  const DevelopResult image = small_image(camera);
  const std::string path = dir.file("shot_000.png");
  std::string error;
  ASSERT_TRUE(write_mask(path, view_of(image.mask, image.width, image.height, 1), &error)) << error;
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().nchannels, 1);
  EXPECT_EQ(in->spec().format, OIIO::TypeDesc::UINT8);
  std::vector<std::uint8_t> pixels(image.mask.size());
  ASSERT_TRUE(in->read_image(0, 0, 0, 1, OIIO::TypeDesc::UINT8, pixels.data()));
  EXPECT_EQ(pixels, image.mask);
}

TEST(DslrWrite, ABufferIsWrittenAtEightBitsWithItsMetadata) {
  rigc::testing::TempDir dir;
  OIIO::ImageBuf image(OIIO::ImageSpec(4, 2, 3, OIIO::TypeDesc::FLOAT));
  const float grey[3] = {0.5f, 0.5f, 0.5f};
  OIIO::ImageBufAlgo::fill(image, grey);
  image.specmod().attribute("Software", "a test");
  const std::string path = dir.file("sheet.png");
  std::string error;
  ASSERT_TRUE(write_image_buffer(path, image, &error)) << error;
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().format, OIIO::TypeDesc::UINT8);
  EXPECT_EQ(in->spec().get_string_attribute("Software"), "a test");
  std::vector<std::uint8_t> pixels(4 * 2 * 3);
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, pixels.data()));
  EXPECT_EQ(pixels, std::vector<std::uint8_t>(4 * 2 * 3, 128));
  // A format OpenImageIO cannot encode in memory is refused before anything is written.
  EXPECT_FALSE(write_image_buffer(dir.file("sheet.unknown-format"), image, &error));
  EXPECT_EQ(folder_entries(dir.path()), std::vector<std::string>{"sheet.png"});
}

TEST(DslrWrite, UnwritablePlacesGiveAnErrorAndLeaveNothing) {
  rigc::testing::TempDir dir;
  const ir::Camera camera = canon_6d();
  const DevelopResult image = small_image(camera);
  std::string error;
  // A folder that does not exist.
  EXPECT_FALSE(write_image(dir.path() / "missing" / "shot.jpg", image, camera, &error));
  EXPECT_THAT(error, HasSubstr("missing"));
  // A "folder" that is a file.
  rigc::testing::write_text(dir.file("file"), "x");
  error.clear();
  EXPECT_FALSE(write_image(dir.path() / "file" / "shot.jpg", image, camera, &error));
  EXPECT_FALSE(error.empty());
  // The target is a folder: the rename fails after the data was written; the temporary goes.
  fs::create_directories(dir.path() / "taken.jpg" / "inside");
  error.clear();
  EXPECT_FALSE(write_image(dir.path() / "taken.jpg", image, camera, &error));
  EXPECT_FALSE(error.empty());
  error.clear();
  EXPECT_FALSE(write_mask(dir.path() / "taken.jpg",
                          view_of(image.mask, image.width, image.height, 1), &error));
  auto entries = folder_entries(dir.path());
  std::sort(entries.begin(), entries.end());
  EXPECT_EQ(entries, (std::vector<std::string>{"file", "taken.jpg"}));
}

TEST(DslrWrite, ReplacesAnExistingFile) {
  rigc::testing::TempDir dir;
  const ir::Camera camera = canon_6d();
  const std::string path = dir.file("shot.jpg");
  rigc::testing::write_text(path, "old");
  std::string error;
  ASSERT_TRUE(write_image(path, small_image(camera), camera, &error)) << error;
  EXPECT_GT(fs::file_size(path), 100u);
}

// A file-size limit (RLIMIT_FSIZE) for the life of the object, with SIGXFSZ ignored: a write past
// it fails with EFBIG, as one on a full disk fails with ENOSPC.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &saved_);
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit limit = saved_;
    limit.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &limit);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &saved_);
    std::signal(SIGXFSZ, old_handler_);
  }

 private:
  rlimit saved_{};
  void (*old_handler_)(int) = nullptr;
};

// libjpeg called exit() when its file could not be written (a crash when the caller was a worker
// thread), and a truncated PNG was renamed to its final name: a failed write leaves nothing.
TEST(DslrWrite, AWriteThatRunsOutOfSpaceFailsAndLeavesNothing) {
  rigc::testing::TempDir dir;
  const ir::Camera camera = canon_6d();
  const DevelopResult image = small_image(camera);
  ir::Camera camera16 = camera;
  camera16.format = ir::ImageFormat::kPng16;
  const DevelopResult image16 = small_image(camera16);
  for (const std::string name : {"shot_000.jpg", "shot_000.png", "shot_000.tif"}) {
    std::string error;
    {
      const FileSizeLimit limit(100);  // the flat test image packs small
      const bool jpeg = name.ends_with(".jpg");
      EXPECT_FALSE(
          write_image(dir.file(name), jpeg ? image : image16, jpeg ? camera : camera16, &error))
          << name;
    }
    EXPECT_THAT(error, HasSubstr("cannot write " + dir.file(name) + ": File too large"));
    EXPECT_TRUE(folder_entries(dir.path()).empty()) << name;
  }
  std::string error;
  {
    const FileSizeLimit limit(20);
    EXPECT_FALSE(write_mask(dir.file("mask.png"), view_of(image.mask, image.width, image.height, 1),
                            &error));
  }
  EXPECT_THAT(error, HasSubstr("File too large"));
  EXPECT_TRUE(folder_entries(dir.path()).empty());
}

}  // namespace
}  // namespace rigc::dslr
