#include "eval/photo_masks.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imageio.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>

#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc::eval {
namespace {

namespace fs = std::filesystem;

// A picture of `channels` channels whose every pixel is `value`, except a square of `inner`.
void write_picture(const fs::path& path, int w, int h, int channels,
                   std::vector<unsigned char> value, std::vector<unsigned char> inner) {
  std::vector<unsigned char> pixels(static_cast<std::size_t>(w) * h * channels);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const bool in = x >= w / 4 && x < 3 * w / 4 && y >= h / 4 && y < 3 * h / 4;
      for (int c = 0; c < channels; ++c) {
        pixels[(static_cast<std::size_t>(y) * w + x) * channels + c] = in ? inner[c] : value[c];
      }
    }
  }
  OIIO::ImageSpec spec(w, h, channels, OIIO::TypeDesc::UINT8);
  if (channels == 4) spec.alpha_channel = 3;
  auto out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out && out->open(path.string(), spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
  ASSERT_TRUE(out->close());
}

ImageSet photo_set(const fs::path& dir, const std::vector<std::string>& names) {
  ImageSet set;
  set.dir = dir;
  set.names = names;
  for (const auto& n : names) {
    write_picture(dir / n, 64, 48, 3, {0, 150, 60}, {160, 150, 140});  // grey on green
    set.size[n] = {64, 48};
  }
  return set;
}

double mask_mean(const fs::path& path) {
  OIIO::ImageBuf mask(path.string());
  float mean = 0;
  EXPECT_TRUE(mask.read(0, 0, true, OIIO::TypeDesc::FLOAT));
  const auto& spec = mask.spec();
  for (int y = 0; y < spec.height; ++y) {
    for (int x = 0; x < spec.width; ++x) mean += mask.getchannel(x, y, 0, 0);
  }
  return mean / (spec.width * spec.height);
}

TEST(PhotoMasks, TheKeyMasksTheObjectAndTheSheetShowsIt) {
  rigc::testing::TempDir dir;
  const ImageSet set = photo_set(dir.path(), {"a.jpg", "b.jpg"});
  PhotoMaskOptions o;
  o.backdrop_color = ir::Vec3(0.0, 0.69, 0.25);
  o.quiet = true;
  std::ostringstream log;
  std::string error;
  const auto masks = make_photo_masks(set, o, dir.path() / "out", log, &error);
  ASSERT_TRUE(masks.has_value()) << error;
  EXPECT_EQ(masks->report["masked_photos"], 2);
  // The grey square, 32 x 24 px, grown by 2 px on every side (JPEG's fringe aside).
  EXPECT_NEAR(mask_mean(dir.path() / "out" / "masks" / "a.png"), 36.0 * 28 / (64 * 48), 0.02);
  EXPECT_TRUE(fs::exists(masks->contact_sheet));
}

TEST(PhotoMasks, MasksMadeElsewhereAreTakenInAnyFormatAndChecked) {
  rigc::testing::TempDir dir;
  const ImageSet set = photo_set(dir.path(), {"a.jpg", "b.jpg", "c.jpg"});
  const fs::path made = dir.path() / "made";
  fs::create_directories(made);
  write_picture(made / "a.tif", 64, 48, 3, {0, 0, 0}, {255, 255, 255});
  write_picture(made / "b.png", 64, 48, 4, {9, 9, 9, 0}, {9, 9, 9, 255});  // the alpha is the mask
  PhotoMaskOptions o;
  o.masks_dir = made.string();
  o.quiet = true;
  std::ostringstream log;
  std::string error;
  const auto masks = make_photo_masks(set, o, dir.path() / "out", log, &error);
  ASSERT_TRUE(masks.has_value()) << error;
  EXPECT_EQ(masks->report["masked_photos"], 2);
  EXPECT_TRUE(masks->report["photos"]["c.jpg"]["mask"].is_null());
  EXPECT_NEAR(mask_mean(dir.path() / "out" / "masks" / "a.png"), 0.25, 1e-6);
  EXPECT_NEAR(mask_mean(dir.path() / "out" / "masks" / "b.png"), 0.25, 1e-6);

  write_picture(made / "a.tif", 32, 24, 1, {0}, {255});
  EXPECT_FALSE(make_photo_masks(set, o, dir.path() / "out", log, &error).has_value());
  EXPECT_THAT(error, HasSubstr("32x24"));
  o.masks_dir = (dir.path() / "empty").string();
  fs::create_directories(o.masks_dir);
  EXPECT_FALSE(make_photo_masks(set, o, dir.path() / "out", log, &error).has_value());
  EXPECT_THAT(error, HasSubstr("no mask for any"));
}

}  // namespace
}  // namespace rigc::eval
