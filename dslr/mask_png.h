// Object masks as 8-bit greyscale PNG files, encoded by runs.
//
// A mask is a few long runs of 0 and 255 per row. zlib's deflate looks at every one of its bytes
// (20 million in a full-resolution shot), which the renderer's cores pay for beside the JPEG.
// This encoder finds the runs with word compares and writes
// each one as a literal and distance-1 matches under deflate's fixed Huffman codes (RFC 1951,
// section 3.2.6), with the Adler-32 checksum of a run in closed form: a valid zlib stream that
// any PNG reader decodes, about as small as zlib's fastest level makes it.
#pragma once

#include <cstdint>
#include <string>

#include "dslr/image_view.h"

namespace rigc::dslr {

// The PNG file (signature, IHDR, one IDAT, IEND) of a single-channel 8-bit image. Any byte
// values are allowed; runs of equal bytes pack best. The view must not be empty.
std::string encode_mask_png(ImageView<const std::uint8_t> mask);

}  // namespace rigc::dslr
