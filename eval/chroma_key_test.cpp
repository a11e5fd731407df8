#include "eval/chroma_key.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace rigc::eval {
namespace {

// A 120 x 80 picture: a green screen (darker towards the bottom, as in a shadow), a dark grey
// turntable band at rows 60..69, and a grey speckled object at columns 50..69, rows 20..64,
// whose speckle changes with `seed` (the object turns).
KeyImage turntable_picture(int seed) {
  KeyImage im;
  im.width = 120;
  im.height = 80;
  im.srgb.resize(im.pixels() * 3);
  std::mt19937 random(seed);
  for (int y = 0; y < im.height; ++y) {
    for (int x = 0; x < im.width; ++x) {
      std::uint8_t* p = &im.srgb[3 * (static_cast<std::size_t>(y) * im.width + x)];
      const double shade = 1.0 - 0.5 * y / im.height;  // the screen darkens downwards
      p[0] = 0;
      p[1] = static_cast<std::uint8_t>(150 * shade);
      p[2] = static_cast<std::uint8_t>(90 * shade);
      if (y >= 60 && y < 70) p[0] = p[1] = p[2] = 30;  // the turntable
      if (x >= 50 && x < 70 && y >= 20 && y < 65) {
        const std::uint8_t v = random() % 2 ? 200 : 90;
        p[0] = v;
        p[1] = v;
        p[2] = static_cast<std::uint8_t>(v - 10);
      }
    }
  }
  return im;
}

std::uint8_t at(const std::vector<std::uint8_t>& mask, int x, int y) {
  return mask[static_cast<std::size_t>(y) * 120 + x];
}

TEST(ChromaKey, BordersGiveTheScreenAndTheKeyKeepsTheObjectThroughShadows) {
  const KeyImage im = turntable_picture(1);
  const auto key = backdrop_at_borders(im, std::nullopt, 0.12);
  ASSERT_TRUE(key.has_value());
  EXPECT_LT(key->r, 0.02);
  EXPECT_GT(key->g, 0.6);
  const auto mask = key_backdrop(im, *key, 0.12);
  EXPECT_EQ(at(mask, 5, 5), 0);      // lit screen
  EXPECT_EQ(at(mask, 5, 75), 0);     // the screen in shadow
  EXPECT_EQ(at(mask, 60, 40), 255);  // the object
  EXPECT_EQ(at(mask, 20, 65), 255);  // the turntable is not green: the chroma key keeps it
}

TEST(ChromaKey, TheScenesColourPicksTheScreenAmongOtherBorderColours) {
  KeyImage im = turntable_picture(1);
  // A red strip along the top border: no longer half the border is one colour without a hint.
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < im.width; ++x) {
      std::uint8_t* p = &im.srgb[3 * (static_cast<std::size_t>(y) * im.width + x)];
      p[0] = 200, p[1] = 20, p[2] = 20;
    }
  }
  const Chroma green = chroma_of_linear({0.0, 0.69, 0.25});
  const auto key = backdrop_at_borders(im, green, 0.12);
  ASSERT_TRUE(key.has_value());
  EXPECT_LT(chroma_distance(*key, green), 0.12);
  // Borders of noise are no backdrop.
  KeyImage noise = im;
  std::mt19937 random(3);
  for (auto& v : noise.srgb) v = static_cast<std::uint8_t>(random());
  EXPECT_FALSE(backdrop_at_borders(noise, std::nullopt, 0.05).has_value());
}

TEST(ChromaKey, TheStillBackgroundTakesTheTurntableAndItsShadowButNotTheTurningObject) {
  std::vector<KeyImage> pictures;
  for (int seed = 0; seed < 8; ++seed) pictures.push_back(turntable_picture(seed));
  // A shadow on the turntable in one photo: darker, the same colour.
  for (int x = 20; x < 40; ++x) {
    std::uint8_t* p = &pictures[3].srgb[3 * (static_cast<std::size_t>(66) * 120 + x)];
    p[0] = p[1] = p[2] = 15;
  }
  std::vector<const KeyImage*> all;
  for (const auto& p : pictures) all.push_back(&p);
  const auto still = still_background(all);
  ASSERT_TRUE(still.has_value());
  EXPECT_GT(still->still_fraction, 0.8);
  const auto moving = key_still(pictures[3], *still);
  EXPECT_EQ(at(moving, 30, 62), 0);    // the turntable
  EXPECT_EQ(at(moving, 30, 66), 0);    // its shadow
  EXPECT_EQ(at(moving, 60, 40), 255);  // the turning object
  // Fewer than five photos: no median to trust.
  EXPECT_FALSE(still_background({all.begin(), all.begin() + 4}).has_value());
}

// A speckle of two tones matches its own median in about half the photos as the object turns:
// that is no still background.
TEST(ChromaKey, ATurningSpeckledObjectIsNotTakenForStill) {
  std::vector<KeyImage> pictures;
  for (int seed = 0; seed < 10; ++seed) pictures.push_back(turntable_picture(seed));
  std::vector<const KeyImage*> all;
  for (const auto& p : pictures) all.push_back(&p);
  const auto still = still_background(all);
  ASSERT_TRUE(still.has_value());
  for (const auto& picture : pictures) {
    const auto moving = key_still(picture, *still);
    int kept = 0, object = 0;
    for (int y = 20; y < 60; ++y) {
      for (int x = 50; x < 70; ++x) {
        kept += at(moving, x, y) == 255;
        ++object;
      }
    }
    EXPECT_GT(kept, 0.85 * object);  // a share of one half keyed away 87 % of it
  }
}

TEST(ChromaKey, CleaningDropsSpecksFillsHolesAndGrows) {
  const int w = 40, h = 30;
  std::vector<std::uint8_t> mask(w * h, 0);
  for (int y = 5; y < 25; ++y) {
    for (int x = 10; x < 30; ++x) mask[y * w + x] = 255;
  }
  mask[15 * w + 20] = 0;  // a hole
  mask[2 * w + 2] = 255;  // a speck
  const auto clean = clean_object_mask(mask, w, h, 1);
  EXPECT_EQ(clean[15 * w + 20], 255);
  EXPECT_EQ(clean[2 * w + 2], 0);
  EXPECT_EQ(clean[4 * w + 15], 255);  // grown by one
  EXPECT_EQ(clean[3 * w + 15], 0);
  const auto big = scale_mask(clean, w, h, 2 * w, 2 * h);
  EXPECT_EQ(big[(2 * 15) * 2 * w + 2 * 20], 255);
  EXPECT_EQ(big[0], 0);
}

}  // namespace
}  // namespace rigc::eval

namespace rigc::eval {
namespace {

// A 100 x 80 picture on black velvet (sRGB 8, a dark grey fold at 30 on the left) with a lit,
// shaded plaster block at columns 40..69, rows 20..59 (sRGB 120 to 230), or the same in a
// light tent (sRGB 245) with a mid-grey block.
KeyImage velvet_picture(bool dark) {
  KeyImage im;
  im.width = 100;
  im.height = 80;
  im.srgb.resize(im.pixels() * 3);
  for (int y = 0; y < im.height; ++y) {
    for (int x = 0; x < im.width; ++x) {
      std::uint8_t* p = &im.srgb[3 * (static_cast<std::size_t>(y) * im.width + x)];
      std::uint8_t v = dark ? (x < 12 ? 30 : 8) : 245;
      if (x >= 40 && x < 70 && y >= 20 && y < 60) {
        v = static_cast<std::uint8_t>(dark ? 120 + 110 * (x - 40) / 30 : 90 + 60 * (x - 40) / 30);
      }
      p[0] = p[1] = v;
      p[2] = static_cast<std::uint8_t>(v * 9 / 10);
    }
  }
  return im;
}

TEST(ChromaKey, BlackVelvetAndALightTentAreKeyedByBrightness) {
  for (const bool dark : {true, false}) {
    const KeyImage im = velvet_picture(dark);
    const auto backdrop = backdrop_brightness_at_borders(im);
    ASSERT_TRUE(backdrop.has_value()) << dark;
    EXPECT_EQ(*backdrop, dark ? BrightBackdrop::kDark : BrightBackdrop::kBright);
    // The key, then the velvet's fold at the frame's edge dropped, as eval's masks do.
    auto mask = key_brightness(im, *backdrop);
    drop_border_components(mask, im.width, im.height);
    int wrong = 0;
    for (int y = 0; y < im.height; ++y) {
      for (int x = 0; x < im.width; ++x) {
        const bool object = x >= 40 && x < 70 && y >= 20 && y < 60;
        wrong += (mask[static_cast<std::size_t>(y) * im.width + x] == 255) != object;
      }
    }
    EXPECT_EQ(wrong, 0) << (dark ? "velvet" : "light tent");
  }
  EXPECT_FALSE(backdrop_brightness_at_borders(turntable_picture(1)).has_value())
      << "a green screen is no brightness backdrop";
}

// A gap the velvet shows through stays out of the mask; a shaded pocket that a key left out
// but that is brighter than the velvet is filled, and so is a speck of the velvet's darkness.
TEST(ChromaKey, TheBackdropSeenThroughTheObjectStaysAHole) {
  KeyImage im = velvet_picture(true);
  const int w = im.width;
  std::vector<std::uint8_t> mask(im.pixels(), 0);
  auto set = [&](int x0, int y0, int x1, int y1, std::uint8_t v, std::uint8_t m) {
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) {
        std::uint8_t* p = &im.srgb[3 * (static_cast<std::size_t>(y) * w + x)];
        p[0] = p[1] = p[2] = v;
        mask[static_cast<std::size_t>(y) * w + x] = m;
      }
    }
  };
  set(40, 20, 70, 60, 180, 255);  // the object, as a key found it
  set(45, 25, 55, 33, 8, 0);      // the velvet through it: 80 pixels of the 1200
  set(45, 45, 55, 53, 30, 0);     // a shaded pocket the key left out
  set(62, 40, 64, 41, 8, 0);      // a speck
  auto at_xy = [&](const std::vector<std::uint8_t>& m, int x, int y) {
    return m[static_cast<std::size_t>(y) * w + x];
  };
  const auto see_through = at_backdrop_level(im, BrightBackdrop::kDark);
  const auto clean = clean_object_mask(mask, w, im.height, 0, &see_through);
  EXPECT_EQ(at_xy(clean, 50, 29), 0);
  EXPECT_EQ(at_xy(clean, 50, 49), 255);
  EXPECT_EQ(at_xy(clean, 62, 40), 255);
  EXPECT_EQ(at_xy(clean, 42, 22), 255);
  // Without the backdrop's level, every hole this large is the backdrop's.
  EXPECT_EQ(at_xy(clean_object_mask(mask, w, im.height, 0), 50, 49), 0);
}

}  // namespace
}  // namespace rigc::eval
