// Turning image data into an 8-bit ir::Texture (internal to assets/): pixels a model file already
// decoded, or encoded image bytes (PNG, JPEG, ...) decoded here.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ir/ir.h"

namespace rigc::loading {

// The most pixels a texture may have (8192 x 8192), checked from its header before decoding.
inline constexpr std::uint64_t kMostTexturePixels = std::uint64_t{1} << 26;

// Converts decoded pixels (8 or 16 bits per channel) to an 8-bit ir::Texture. `what` names the
// image in a LoadError.
// (Seven parameters: a decoder's output as the decoders hand it over.)
ir::Texture make_texture(std::string source, int width, int height, int channels, int bits,
                         const std::vector<unsigned char>& data, const std::string& what);

// Decodes an encoded image (PNG, JPEG, ...) with the stb_image inside tinygltf.
ir::Texture decode_image(std::string source, const std::vector<unsigned char>& bytes,
                         const std::string& what);

}  // namespace rigc::loading
