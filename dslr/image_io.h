// Writing developed images and masks: atomic (a temporary file in the same folder, then a
// rename), with the EXIF a photogrammetry tool reads. Errors are returned, never thrown.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "dslr/frame.h"
#include "ir/ir.h"

namespace rigc::dslr {

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
bool write_mask(const std::filesystem::path& path, const std::vector<std::uint8_t>& mask, int width,
                int height, std::string* error);

}  // namespace rigc::dslr
