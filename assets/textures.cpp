#include "assets/textures.h"

#include <stb/stb_image.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string_view>
#include <utility>

#include "assets/model_loading.h"

namespace rigc::loading {
namespace {

// A PNG's size, channels and bit depth from its header (IHDR, which the format puts first), or
// nothing if `bytes` is no PNG or the header is broken. Read for the size when stb_image's header
// test refuses a PNG as too large for it.
struct PngHeader {
  std::uint32_t width = 0, height = 0;
  int channels = 0;
  int bits = 0;
};
std::optional<PngHeader> png_header(const std::vector<unsigned char>& bytes) {
  static constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (bytes.size() < 33 || !std::equal(kSignature, kSignature + 8, bytes.begin()) ||
      std::string_view(reinterpret_cast<const char*>(bytes.data()) + 8, 8) !=
          std::string_view("\0\0\0\x0dIHDR", 8)) {
    return std::nullopt;
  }
  const auto big_endian = [&](std::size_t at) {
    return std::uint32_t{bytes[at]} << 24 | std::uint32_t{bytes[at + 1]} << 16 |
           std::uint32_t{bytes[at + 2]} << 8 | std::uint32_t{bytes[at + 3]};
  };
  PngHeader header{big_endian(16), big_endian(20), 0, bytes[24]};
  if (header.bits != 1 && header.bits != 2 && header.bits != 4 && header.bits != 8 &&
      header.bits != 16) {
    return std::nullopt;
  }
  // Channels by colour type (grey, -, RGB, palette, grey + alpha, -, RGBA); a palette counts as
  // 4, as stb_image counts it.
  static constexpr int kChannels[7] = {1, 0, 3, 4, 2, 0, 4};
  if (bytes[25] >= 7 || kChannels[bytes[25]] == 0) return std::nullopt;
  header.channels = kChannels[bytes[25]];
  return header;
}

// Fails for a texture of more than kMostTexturePixels: the renderers keep every texture whole in
// memory, several copies of it, whatever share of it a photo shows.
void check_texture_size(std::uint64_t width, std::uint64_t height, const std::string& what) {
  if (width * height > kMostTexturePixels) {
    fail(
        "{} is {} x {} pixels: more than the {} megapixels a texture may have (8192 x 8192); "
        "scale it down",
        what, width, height, kMostTexturePixels >> 20);
  }
}

}  // namespace

ir::Texture make_texture(std::string source, int width, int height, int channels, int bits,
                         const std::vector<unsigned char>& data, const std::string& what) {
  if (width <= 0 || height <= 0 || channels < 1 || channels > 4 || (bits != 8 && bits != 16)) {
    fail("{} has an unsupported pixel format ({}x{}, {} channels, {} bits)", what, width, height,
         channels, bits);
  }
  check_texture_size(width, height, what);
  const std::size_t n = static_cast<std::size_t>(width) * height * channels;
  if (data.size() != n * (bits / 8)) fail("{} has truncated pixel data", what);
  ir::Texture tex;
  tex.source = std::move(source);
  tex.width = width;
  tex.height = height;
  tex.channels = channels;
  if (bits == 8) {
    tex.pixels.assign(data.begin(), data.end());
  } else {
    tex.pixels.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      std::uint16_t v;
      std::memcpy(&v, data.data() + 2 * i, 2);
      tex.pixels[i] = static_cast<std::uint8_t>((v + 128U) / 257U);
    }
  }
  return tex;
}

ir::Texture decode_image(std::string source, const std::vector<unsigned char>& bytes,
                         const std::string& what) {
  if (bytes.empty() || bytes.size() > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    fail("{} is empty or too large", what);
  }
  // From the header, before decoding: a 775 KB PNG can hold 16000 x 16000 pixels.
  int width = 0, height = 0, channels = 0;
  if (stbi_info_from_memory(bytes.data(), static_cast<int>(bytes.size()), &width, &height,
                            &channels)) {
    check_texture_size(static_cast<std::uint64_t>(width), static_cast<std::uint64_t>(height), what);
  } else if (const std::optional<PngHeader> png = png_header(bytes)) {
    check_texture_size(png->width, png->height, what);  // a size stb_image's header test refuses
  }
  tinygltf::Image image;
  std::string err, warn;
  if (!tinygltf::LoadImageData(&image, 0, &err, &warn, 0, 0, bytes.data(),
                               static_cast<int>(bytes.size()), nullptr)) {
    fail("{} could not be decoded (unknown or broken image format)", what);
  }
  return make_texture(std::move(source), image.width, image.height, image.component, image.bits,
                      image.image, what);
}

}  // namespace rigc::loading
