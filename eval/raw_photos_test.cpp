#include "eval/raw_photos.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "eval/photo_camera.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc::eval {
namespace {

namespace fs = std::filesystem;

// A minimal DNG, as a camera's raw converter writes one: one uncompressed 16-bit RGGB Bayer
// strip, a Canon 6D's make and model, a 50 mm focal length, and an as-shot white balance that
// makes a raw (R, G, B) = (0.5, 1, 0.8) x v neutral. Little-endian TIFF.
class DngWriter {
 public:
  void entry(std::uint16_t tag, std::uint16_t type, std::uint32_t count, std::string payload) {
    entries_.push_back({tag, type, count, std::move(payload)});
  }
  template <typename T>
  static std::string bytes_of(const std::vector<T>& values) {
    return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
  }
  std::string build(const std::string& pixel_data) const {
    // Header, then the IFD, then the out-of-line values, then the pixels.
    const std::uint32_t ifd_offset = 8;
    const std::uint32_t ifd_size = 2 + 12 * static_cast<std::uint32_t>(entries_.size()) + 4;
    std::string ifd, extra;
    auto put16 = [](std::string& s, std::uint16_t v) { s.append(reinterpret_cast<char*>(&v), 2); };
    auto put32 = [](std::string& s, std::uint32_t v) { s.append(reinterpret_cast<char*>(&v), 4); };
    const std::uint32_t extra_start = ifd_offset + ifd_size;
    std::uint32_t total_extra = 0;
    for (const auto& e : entries_)
      total_extra += e.payload.size() > 4 ? (e.payload.size() + 1) & ~1u : 0;
    const std::uint32_t pixels_at = extra_start + total_extra;
    put16(ifd, static_cast<std::uint16_t>(entries_.size()));
    for (const auto& e : entries_) {
      put16(ifd, e.tag);
      put16(ifd, e.type);
      put32(ifd, e.count);
      std::string payload = e.tag == kStripOffsets ? std::string(4, '\0') : e.payload;
      if (e.tag == kStripOffsets) std::memcpy(payload.data(), &pixels_at, 4);
      if (payload.size() <= 4) {
        payload.resize(4, '\0');
        ifd += payload;
      } else {
        put32(ifd, extra_start + static_cast<std::uint32_t>(extra.size()));
        extra += payload;
        if (extra.size() % 2) extra += '\0';
      }
    }
    put32(ifd, 0);
    std::string file = "II";
    put16(file, 42);
    put32(file, ifd_offset);
    return file + ifd + extra + pixel_data;
  }
  static constexpr std::uint16_t kStripOffsets = 273;

 private:
  struct Entry {
    std::uint16_t tag, type;
    std::uint32_t count;
    std::string payload;
  };
  std::vector<Entry> entries_;
};

enum : std::uint16_t {
  kByte = 1,
  kAscii = 2,
  kShort = 3,
  kLong = 4,
  kRational = 5,
  kSRational = 10
};

std::string ascii(const std::string& text) {
  return text + '\0';
}

void write_test_dng(const fs::path& path, int w, int h, double v) {
  std::vector<std::uint16_t> pixels(static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      // RGGB: red at even rows and columns, blue at odd ones, green between.
      const double gain = (y % 2 == 0 && x % 2 == 0) ? 0.5 : (y % 2 && x % 2) ? 0.8 : 1.0;
      pixels[static_cast<std::size_t>(y) * w + x] = static_cast<std::uint16_t>(65535 * v * gain);
    }
  }
  const std::string make = "Canon", model = "Canon EOS 6D";
  DngWriter d;
  using B = DngWriter;
  d.entry(254, kLong, 1, B::bytes_of(std::vector<std::uint32_t>{0}));
  d.entry(256, kLong, 1, B::bytes_of(std::vector<std::uint32_t>{std::uint32_t(w)}));
  d.entry(257, kLong, 1, B::bytes_of(std::vector<std::uint32_t>{std::uint32_t(h)}));
  d.entry(258, kShort, 1, B::bytes_of(std::vector<std::uint16_t>{16}));
  d.entry(259, kShort, 1, B::bytes_of(std::vector<std::uint16_t>{1}));
  d.entry(262, kShort, 1, B::bytes_of(std::vector<std::uint16_t>{32803}));  // CFA
  d.entry(271, kAscii, make.size() + 1, ascii(make));
  d.entry(272, kAscii, model.size() + 1, ascii(model));
  d.entry(DngWriter::kStripOffsets, kLong, 1, std::string(4, '\0'));
  d.entry(277, kShort, 1, B::bytes_of(std::vector<std::uint16_t>{1}));
  d.entry(278, kLong, 1, B::bytes_of(std::vector<std::uint32_t>{std::uint32_t(h)}));
  d.entry(279, kLong, 1, B::bytes_of(std::vector<std::uint32_t>{std::uint32_t(w * h * 2)}));
  d.entry(284, kShort, 1, B::bytes_of(std::vector<std::uint16_t>{1}));
  d.entry(33421, kShort, 2, B::bytes_of(std::vector<std::uint16_t>{2, 2}));
  d.entry(33422, kByte, 4, std::string("\x00\x01\x01\x02", 4));
  d.entry(37386, kRational, 1, B::bytes_of(std::vector<std::uint32_t>{50, 1}));  // FocalLength
  d.entry(50706, kByte, 4, std::string("\x01\x04\x00\x00", 4));                  // DNGVersion
  d.entry(50708, kAscii, model.size() + 1, ascii(model));                    // UniqueCameraModel
  d.entry(50714, kLong, 1, B::bytes_of(std::vector<std::uint32_t>{0}));      // BlackLevel
  d.entry(50717, kLong, 1, B::bytes_of(std::vector<std::uint32_t>{65535}));  // WhiteLevel
  // ColorMatrix1 (XYZ -> camera): the inverse of sRGB's, in ten-thousandths.
  d.entry(50721, kSRational, 9,
          B::bytes_of(std::vector<std::int32_t>{32406, 10000, -15372, 10000, -4986, 10000, -9689,
                                                10000, 18758, 10000, 415, 10000, 557, 10000, -2040,
                                                10000, 10570, 10000}));
  d.entry(50728, kRational, 3,
          B::bytes_of(std::vector<std::uint32_t>{1, 2, 1, 1, 4, 5}));      // AsShotNeutral
  d.entry(50778, kShort, 1, B::bytes_of(std::vector<std::uint16_t>{21}));  // D65
  std::ofstream(path, std::ios::binary) << d.build(DngWriter::bytes_of(pixels));
}

TEST(RawPhotos, ADngIsDevelopedWithItsWhiteBalanceIntoSrgbAndCached) {
  rigc::testing::TempDir dir;
  const fs::path raw = dir.path() / "IMG_0001.DNG";
  write_test_dng(raw, 64, 48, 0.18);
  EXPECT_TRUE(is_raw_photo(raw));
  EXPECT_FALSE(is_raw_photo("a.jpg"));
  const fs::path jpeg = dir.path() / "IMG_0001.jpg";
  bool cached = true;
  std::string error;
  ASSERT_TRUE(develop_raw(raw, jpeg, &cached, &error)) << error;
  EXPECT_FALSE(cached);
  OIIO::ImageBuf developed(jpeg.string());
  ASSERT_TRUE(developed.read(0, 0, true, OIIO::TypeDesc::FLOAT)) << developed.geterror();
  ASSERT_EQ(developed.nativespec().format, OIIO::TypeDesc::UINT8);
  EXPECT_GE(developed.spec().width, 60);
  std::vector<float> mean(3, 0);
  const int cx = developed.spec().width / 2, cy = developed.spec().height / 2;
  developed.getpixel(cx, cy, mean.data());
  // The as-shot white balance makes the grey card grey; sRGB's transfer lifts linear 0.18.
  EXPECT_NEAR(mean[0], mean[1], 0.04) << mean[0] << " " << mean[1] << " " << mean[2];
  EXPECT_NEAR(mean[2], mean[1], 0.04) << mean[0] << " " << mean[1] << " " << mean[2];
  EXPECT_GT(mean[1], 0.3) << "encoded, not linear";
  // The EXIF goes along: the camera is found from the developed photo.
  const PhotoExif exif = read_photo_exif(jpeg);
  const auto body = preset_for_exif(exif.make, exif.model);
  ASSERT_TRUE(body.has_value()) << exif.make << " / " << exif.model;
  EXPECT_EQ(body->name, "canon-6d");
  EXPECT_NEAR(exif.focal_mm, 50, 1e-3);
  ASSERT_TRUE(develop_raw(raw, jpeg, &cached, &error)) << error;
  EXPECT_TRUE(cached);
}

TEST(RawPhotos, ARawAndItsJpegAreOnePhotoAndABrokenRawIsNamed) {
  rigc::testing::TempDir dir;
  const fs::path photos = dir.path() / "photos";
  fs::create_directories(photos);
  write_test_dng(photos / "IMG_0001.DNG", 64, 48, 0.18);
  rigc::testing::write_text((photos / "IMG_0001.JPG").string(), "the camera's JPEG");
  ImageSet set;
  set.dir = photos;
  set.names = {"IMG_0001.DNG", "IMG_0001.JPG"};
  std::ostringstream log;
  std::string error;
  ASSERT_TRUE(develop_raw_photos(set, dir.path() / "out", log, true, &error)) << error;
  EXPECT_EQ(set.dir, dir.path() / "out" / "developed");
  EXPECT_EQ(set.names, std::vector<std::string>{"IMG_0001.jpg"});
  EXPECT_EQ(set.size.at("IMG_0001.jpg").first, 64);

  rigc::testing::write_text((photos / "IMG_0002.NEF").string(), "not a raw file");
  set.dir = photos;
  set.names = {"IMG_0002.NEF"};
  EXPECT_FALSE(develop_raw_photos(set, dir.path() / "out", log, true, &error));
  EXPECT_THAT(error, HasSubstr("IMG_0002.NEF"));
}

// Photos in eval's own OUT/developed: the RAW's developed JPEG would replace the camera's JPEG
// of that name, and a JPEG would be replaced by a link to itself. eval refuses instead.
TEST(RawPhotos, PhotosInTheDevelopedFolderAreNeitherReplacedNorLinkedToThemselves) {
  rigc::testing::TempDir dir;
  const fs::path developed = dir.path() / "out" / "developed";
  fs::create_directories(developed);
  write_test_dng(developed / "IMG_0001.DNG", 64, 48, 0.18);
  OIIO::ImageBuf grey(OIIO::ImageSpec(64, 48, 3, OIIO::TypeDesc::UINT8));
  OIIO::ImageBufAlgo::fill(grey, {0.5f, 0.5f, 0.5f});
  for (const char* name : {"IMG_0001.jpg", "IMG_0002.jpg"}) {
    ASSERT_TRUE(grey.write((developed / name).string()));
  }
  const std::string camera_jpeg = rigc::testing::read_text((developed / "IMG_0001.jpg").string());
  const auto r = rigc::testing::run_rigc(
      {"eval", "--photos", developed.string(), "-o", (dir.path() / "out").string()});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_THAT(r.err, HasSubstr("will not write " + (developed / "IMG_0001.jpg").string()));
  EXPECT_EQ(rigc::testing::read_text((developed / "IMG_0001.jpg").string()), camera_jpeg);
  EXPECT_FALSE(fs::is_symlink(developed / "IMG_0002.jpg"));
}

}  // namespace
}  // namespace rigc::eval
