// Turning image data into an 8-bit ir::Texture (internal to assets/): pixels a model file already
// decoded, or encoded image bytes (PNG, JPEG, ...) decoded here.
#pragma once

#include <string>
#include <vector>

#include "ir/ir.h"

namespace rigc::loading {

// Converts decoded pixels (8 or 16 bits per channel) to an 8-bit ir::Texture. `what` names the
// image in a LoadError.
ir::Texture make_texture(std::string source, int width, int height, int channels, int bits,
                         const std::vector<unsigned char>& data, const std::string& what);

// Decodes an encoded image (PNG, JPEG, ...) with the stb_image inside tinygltf.
ir::Texture decode_image(std::string source, const std::vector<unsigned char>& bytes,
                         const std::string& what);

}  // namespace rigc::loading
