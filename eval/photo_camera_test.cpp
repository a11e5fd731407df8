#include "eval/photo_camera.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>

#include "eval/colmap.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc::eval {
namespace {

namespace fs = std::filesystem;

// A small JPEG with the EXIF a camera writes (nothing when make is empty).
void write_photo(const fs::path& path, int w, int h, const std::string& make,
                 const std::string& model, float focal_mm, const std::string& taken = "") {
  OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::UINT8);
  if (!make.empty()) {
    spec.attribute("Make", make);
    spec.attribute("Model", model);
    spec.attribute("Exif:FocalLength", focal_mm);
  }
  if (!taken.empty()) spec.attribute("Exif:DateTimeOriginal", taken);
  const std::vector<unsigned char> pixels(static_cast<std::size_t>(w) * h * 3, 100);
  auto out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out && out->open(path.string(), spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
  ASSERT_TRUE(out->close());
}

ImageSet image_set(const fs::path& dir, const std::vector<std::string>& names, int w, int h) {
  ImageSet set;
  set.dir = dir;
  set.names = names;
  for (const auto& n : names) set.size[n] = {w, h};
  return set;
}

TEST(PhotoCamera, TheStatementNamesABodyAndAFocalLength) {
  std::string error;
  const auto s = parse_camera_statement("canon-6d,50mm", &error);
  ASSERT_TRUE(s.has_value()) << error;
  EXPECT_EQ(s->body.name, "canon-6d");
  EXPECT_DOUBLE_EQ(s->focal_mm, 50);
  EXPECT_TRUE(parse_camera_statement("nikon-d850,35", &error).has_value());
  EXPECT_FALSE(parse_camera_statement("canon-6d", &error).has_value());
  EXPECT_THAT(error, HasSubstr("BODY,FOCAL"));
  EXPECT_FALSE(parse_camera_statement("leica-m3,50mm", &error).has_value());
  EXPECT_THAT(error, HasSubstr("canon-6d")) << "the known bodies are listed";
  EXPECT_FALSE(parse_camera_statement("canon-6d,fiftymm", &error).has_value());
  EXPECT_FALSE(parse_camera_statement("canon-6d,-5mm", &error).has_value());
}

TEST(PhotoCamera, ExifMakeAndModelFindThePresetAndItsSensorGivesPixels) {
  const auto p = preset_for_exif("Canon", "  Canon EOS 6D ");
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(p->name, "canon-6d");
  EXPECT_EQ(preset_for_exif("Canon", "EOS 6D")->name, "canon-6d") << "as LibRaw gives it";
  EXPECT_FALSE(preset_for_exif("Canon", "Canon EOS R5").has_value());
  EXPECT_FALSE(preset_for_exif("SONY", "Canon EOS 6D").has_value());
  // Full size: 50 mm on a 35.8 mm wide sensor of 5472 px; a portrait photo uses its long side.
  EXPECT_NEAR(focal_length_px(*p, 50, 5472, 3648), 50 / 35.8 * 5472, 1e-9);
  EXPECT_NEAR(focal_length_px(*p, 50, 547, 821), 50 / 35.8 * 821, 1e-9);
}

TEST(PhotoCamera, EachBodyAndZoomGetsACameraAndTheStatementCoversMissingExif) {
  rigc::testing::TempDir dir;
  write_photo(dir.path() / "a.jpg", 96, 64, "Canon", "Canon EOS 6D", 50);
  write_photo(dir.path() / "b.jpg", 96, 64, "Canon", "Canon EOS 6D", 50);
  write_photo(dir.path() / "c.jpg", 96, 64, "Canon", "Canon EOS 6D", 35);
  write_photo(dir.path() / "d.jpg", 96, 64, "NIKON CORPORATION", "NIKON D850", 50);
  write_photo(dir.path() / "e.jpg", 96, 64, "", "", 0);
  const ImageSet set = image_set(dir.path(), {"a.jpg", "b.jpg", "c.jpg", "d.jpg", "e.jpg"}, 96, 64);
  std::string error;
  const auto cameras = photo_cameras(set, "", &error);
  ASSERT_TRUE(cameras.has_value()) << error;
  ASSERT_EQ(cameras->size(), 4u);
  EXPECT_EQ((*cameras)[0].images, (std::vector<std::string>{"a.jpg", "b.jpg"}));
  EXPECT_TRUE((*cameras)[0].sensor_known);
  EXPECT_NEAR((*cameras)[0].focal_px, 50 / 35.8 * 96, 1e-3);
  EXPECT_NEAR((*cameras)[1].focal_px, 35 / 35.8 * 96, 1e-3);
  EXPECT_NEAR((*cameras)[2].focal_px, 50 / 35.9 * 96, 1e-3);
  EXPECT_EQ((*cameras)[3].focal_px, 0) << "no EXIF: COLMAP guesses";
  EXPECT_FALSE((*cameras)[3].sensor_known);
  // The statement is every photo's camera.
  const auto stated = photo_cameras(set, "canon-6d,50mm", &error);
  ASSERT_TRUE(stated.has_value()) << error;
  ASSERT_EQ(stated->size(), 1u);
  EXPECT_EQ((*stated)[0].images.size(), 5u);
  EXPECT_THAT((*stated)[0].source, HasSubstr("--camera"));
}

// EXIF's focal length 50/0 reads as inf: neither it, 0 nor 1e9 mm reaches COLMAP, and the body
// is named as the preset it is.
TEST(PhotoCamera, AnExifFocalLengthThatIsNoneIsNamedAndNotUsed) {
  rigc::testing::TempDir dir;
  const float focals[] = {std::numeric_limits<float>::infinity(), 0.0f, 1e9f};
  std::vector<std::string> names;
  for (int k = 0; k < 3; ++k) {
    names.push_back(fmt::format("{}.jpg", k));
    write_photo(dir.path() / names.back(), 96, 64, "Canon", "Canon EOS 6D", focals[k]);
  }
  std::string error;
  const auto cameras = photo_cameras(image_set(dir.path(), names, 96, 64), "", &error);
  ASSERT_TRUE(cameras.has_value()) << error;
  for (const auto& camera : *cameras) {
    EXPECT_EQ(camera.focal_px, 0) << camera.source;
    EXPECT_FALSE(camera.sensor_known);
    EXPECT_THAT(camera.source, HasSubstr("is body preset canon-6d, but its EXIF focal length ("));
  }
  EXPECT_FALSE(is_focal_length_mm(std::numeric_limits<double>::infinity()));
  EXPECT_FALSE(is_focal_length_mm(1e9));
  EXPECT_TRUE(is_focal_length_mm(50));
}

TEST(PhotoCamera, CaptureOrderFollowsExifTimeElseTheFileNames) {
  rigc::testing::TempDir dir;
  write_photo(dir.path() / "IMG_0001.jpg", 64, 64, "Canon", "Canon EOS 6D", 50,
              "2026:11:27 10:00:05");
  write_photo(dir.path() / "IMG_0002.jpg", 64, 64, "Canon", "Canon EOS 6D", 50,
              "2026:11:27 10:00:01");
  const ImageSet set = image_set(dir.path(), {"IMG_0001.jpg", "IMG_0002.jpg"}, 64, 64);
  std::string basis;
  EXPECT_EQ(capture_order(set, &basis), (std::vector<std::string>{"IMG_0002.jpg", "IMG_0001.jpg"}));
  EXPECT_EQ(basis, "EXIF time taken");
  write_photo(dir.path() / "IMG_0002.jpg", 64, 64, "Canon", "Canon EOS 6D", 50);
  EXPECT_EQ(capture_order(set, &basis), set.names);
  EXPECT_EQ(basis, "file names");
}

TEST(PhotoCamera, SequentialRingPairsCloseTheLoop) {
  const auto pairs = sequential_ring_pairs(6, 2);
  const std::vector<std::pair<int, int>> expected = {{0, 1}, {0, 2}, {0, 4}, {0, 5},
                                                     {1, 2}, {1, 3}, {1, 5}, {2, 3},
                                                     {2, 4}, {3, 4}, {3, 5}, {4, 5}};
  EXPECT_EQ(pairs, expected);
  EXPECT_EQ(sequential_ring_pairs(3, 3).size(), 3u) << "no pair twice, none of a view with itself";
}

}  // namespace
}  // namespace rigc::eval
