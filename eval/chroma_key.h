// Object masks for photos, made from the pictures alone: a chroma key on the backdrop (a green
// screen: its shadows key like the lit screen, since only the chromaticity counts) and, for a
// turntable capture (a camera that stays put while the object turns), a key on what stays still
// from photo to photo: the turntable, its stand and the floor, with the shadows and the green
// spill on them. What is left is the object, cleaned of specks and holes.
#pragma once

#include <OpenImageIO/imagebuf.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "ir/ir.h"

namespace rigc::eval {

// A photo at working resolution: 8-bit sRGB, row-major, 3 bytes a pixel.
struct KeyImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> srgb;
  std::size_t pixels() const { return static_cast<std::size_t>(width) * height; }
};

// Reads an image's first subimage as 8 bits a channel into `image`; false with `error`.
bool read_uint8_image(const std::filesystem::path& path, OIIO::ImageBuf& image, std::string* error);

// Reads any image OpenImageIO reads (its first three channels, grey repeated) scaled so that
// its long side is at most max_side. nullopt with `error` when it cannot.
std::optional<KeyImage> read_key_image(const std::filesystem::path& path, int max_side,
                                       std::string* error);

// Chromaticity (R, G) / (R + G + B) of linear RGB: the brightness drops out.
struct Chroma {
  double r = 0, g = 0;
};
Chroma chroma_of_linear(const ir::Vec3& linear_rgb);
double chroma_distance(const Chroma& a, const Chroma& b);

// The backdrop's chromaticity at the image's borders: the median over the border pixels (those
// near `hint`, the scene's green screen, when it is given). nullopt when fewer than half of the
// border pixels are within `tolerance` of it: the borders are no one backdrop.
std::optional<Chroma> backdrop_at_borders(const KeyImage& image, const std::optional<Chroma>& hint,
                                          double tolerance);

// 255 where a pixel is not the backdrop (chromaticity farther than `tolerance` from `key`, or
// too dark to tell), 0 where it is.
std::vector<std::uint8_t> key_backdrop(const KeyImage& image, const Chroma& key, double tolerance);

// A backdrop keyed by brightness, not colour: black velvet or a light tent, where chromaticity
// says nothing (too dark) or the object may share its white.
enum class BrightBackdrop { kDark, kBright };

// kDark when nine border pixels in ten are darker than a twentieth of full scale (linear), kBright
// when they are brighter than four fifths; nullopt otherwise.
std::optional<BrightBackdrop> backdrop_brightness_at_borders(const KeyImage& image);

// 255 where a pixel's luminance is on the object's side of a threshold a fifth of the way from
// the one that best splits the image's histogram in two (Otsu's) towards the backdrop, 0 where
// it is the backdrop's.
std::vector<std::uint8_t> key_brightness(const KeyImage& image, BrightBackdrop backdrop);

// 255 where a pixel is as dark (kDark) or as bright (kBright) as the backdrop at the image's
// borders: where a hole in the object's mask is the backdrop seen through it, and not a shaded
// face that key_brightness's threshold, set towards the backdrop's side, also leaves out.
std::vector<std::uint8_t> at_backdrop_level(const KeyImage& image, BrightBackdrop backdrop);

// Removes the object pixels of the components that touch the image's border: with a brightness
// key, the folds of the velvet at the frame's edge, not the object, which is in frame.
void drop_border_components(std::vector<std::uint8_t>& mask, int width, int height);

// What stays still across photos of one size taken from one place: per pixel, the median colour
// and the share of the photos that show it there.
struct StillBackground {
  int width = 0, height = 0;
  std::vector<std::uint8_t> median_srgb;
  std::vector<float> still_share;
  double still_fraction = 0;  // the share of pixels still in 8 photos in 10 or more
};
// nullopt for fewer than 5 photos (no median to trust) or photos of different sizes.
std::optional<StillBackground> still_background(const std::vector<const KeyImage*>& images);

// 255 where a pixel is not the still background: where most photos agree on the background (8
// in 10 or more), a pixel that matches it or is a shadow of it (darker, same chromaticity) is
// background; elsewhere every pixel is kept.
std::vector<std::uint8_t> key_still(const KeyImage& image, const StillBackground& still);

// The object from a raw key: specks opened away, the components much smaller than the largest
// dropped, holes filled but for the backdrop seen through the object (a gap of at least a
// hundredth of the object's area, of pixels that `see_through` marks 255 when it is given), and
// the outline grown by `grow_px` so features on the silhouette keep their support.
std::vector<std::uint8_t> clean_object_mask(std::vector<std::uint8_t> mask, int width, int height,
                                            int grow_px,
                                            const std::vector<std::uint8_t>* see_through = nullptr);

// `mask` (width x height) scaled to to_width x to_height, nearest neighbour.
std::vector<std::uint8_t> scale_mask(const std::vector<std::uint8_t>& mask, int width, int height,
                                     int to_width, int to_height);

}  // namespace rigc::eval
