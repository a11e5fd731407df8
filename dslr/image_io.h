// Writing developed images and masks: atomic (a temporary file in the same folder, then a
// rename), with the EXIF a photogrammetry tool reads. Errors are returned, never thrown.
#pragma once

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imageio.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "dslr/frame.h"
#include "dslr/image_view.h"
#include "ir/ir.h"

namespace rigc::dslr {

// Encodes `pixels` (laid out as `spec` says) in memory in the format the path's extension asks for,
// then writes the bytes with write_file_atomically (io/atomic_file.h). The codecs never touch the
// disk: on a full disk libjpeg's writer called exit() from a worker thread (a crash), and libpng's
// left a truncated PNG that was renamed to its final name. A failed write leaves no file at the
// final name and no temporary; false with *error set ("cannot write PATH: WHY").
bool write_pixels(const std::filesystem::path& path, const OIIO::ImageSpec& spec,
                  const void* pixels, std::string* error);

// Writes `image` at 8 bits a channel with its metadata, encoded like write_pixels in the format
// the path's extension asks for.
bool write_image_buffer(const std::filesystem::path& path, const OIIO::ImageBuf& image,
                        std::string* error);

// Writes result.encoded (or result.encoded_bytes when that holds the codes); the file type follows
// the path's extension (.jpg, .png, .tif). JPEG uses camera.jpeg_quality and is always 8-bit.
// Metadata: Make, Model, Exif:FocalLength (mm), FNumber, ExposureTime, Exif:PhotographicSensitivity
// (ISO), Exif:FocalLengthIn35mmFilm, and Exif:FocalPlaneX/YResolution in pixels per cm (unit 3) of
// this image, so tools can derive the focal length in pixels. Returns false and sets *error on
// failure; no partial file is left.
bool write_image(const std::filesystem::path& path, const DevelopResult& result,
                 const ir::Camera& camera, std::string* error);

// Writes an 8-bit single-channel mask (0/255) atomically: a PNG encoded by runs for a .png path
// (encode_mask_png), otherwise the format OpenImageIO gives the extension.
bool write_mask(const std::filesystem::path& path, ImageView<const std::uint8_t> mask,
                std::string* error);

}  // namespace rigc::dslr
