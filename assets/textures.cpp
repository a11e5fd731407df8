#include "assets/textures.h"

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
// nothing if `bytes` is no PNG or the header is broken. Read only to explain a decoding failure:
// stb_image refuses a PNG too large for it, and tinygltf reports every failure alike.
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

}  // namespace

ir::Texture make_texture(std::string source, int width, int height, int channels, int bits,
                         const std::vector<unsigned char>& data, const std::string& what) {
  if (width <= 0 || height <= 0 || channels < 1 || channels > 4 || (bits != 8 && bits != 16)) {
    fail("{} has an unsupported pixel format ({}x{}, {} channels, {} bits)", what, width, height,
         channels, bits);
  }
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
  tinygltf::Image image;
  std::string err, warn;
  if (!tinygltf::LoadImageData(&image, 0, &err, &warn, 0, 0, bytes.data(),
                               static_cast<int>(bytes.size()), nullptr)) {
    if (const std::optional<PngHeader> png = png_header(bytes)) {
      // stb_image's two limits: its header test (under 1 GB in the file's own channels, in its
      // integer arithmetic), and the RGBA image tinygltf asks for (under 2 GB, at 16 bits for a
      // 16-bit file).
      const double rgba_bytes =
          static_cast<double>(png->width) * png->height * 4 * (png->bits == 16 ? 2 : 1);
      if (png->width > 0 && ((std::uint32_t{1} << 30) / png->width / png->channels < png->height ||
                             rgba_bytes > std::numeric_limits<int>::max())) {
        fail(
            "{} is {} x {} pixels{}: more than the image decoder takes (under 1 GB in the file's "
            "channels and 2 GB as RGBA); scale it down (16384 x 16384 at 8 bits fits)",
            what, png->width, png->height, png->bits == 16 ? " at 16 bits" : "");
      }
    }
    fail("{} could not be decoded (unknown or broken image format)", what);
  }
  return make_texture(std::move(source), image.width, image.height, image.component, image.bits,
                      image.image, what);
}

}  // namespace rigc::loading
