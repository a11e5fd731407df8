#include "dslr/image_view.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace rigc::dslr {
namespace {

TEST(ImageView, ViewsAVectorOfExactlyTheImagesValues) {
  std::vector<float> rgb(4 * 3 * 3, 0.5f);
  const ImageView<float> view = view_of(rgb, 4, 3);
  EXPECT_EQ(view.values, rgb.data());
  EXPECT_EQ(view.pixels(), 12u);
  EXPECT_EQ(view.size(), rgb.size());
  const ImageView<const float> reading = view;  // a writable view also reads
  EXPECT_EQ(reading.values, rgb.data());
  EXPECT_EQ(reading.channels, 3);
}

TEST(ImageView, AVectorOfAnotherSizeGivesAnEmptyView) {
  const std::vector<std::uint8_t> mask(4 * 3);
  EXPECT_FALSE(view_of(mask, 4, 3, 1).empty());
  EXPECT_TRUE(view_of(mask, 4, 3).empty());  // three channels: too few values
  EXPECT_TRUE(view_of(mask, 5, 3, 1).empty());
  EXPECT_TRUE(view_of(mask, 0, 0, 1).empty());
  EXPECT_EQ(view_of(mask, -4, -3, 1).values, nullptr);
}

}  // namespace
}  // namespace rigc::dslr
