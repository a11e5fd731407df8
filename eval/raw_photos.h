// RAW photos (CR2, NEF, ARW, DNG and the other formats LibRaw reads), developed for COLMAP
// through OpenImageIO's raw reader the way RigC's preview develops a frame: the white balance
// the camera recorded in the file, sRGB primaries and transfer, 8 bits. The developments are
// cached in OUT/developed (a RAW is developed again only when it is newer than its JPEG).
#pragma once

#include <filesystem>
#include <ostream>
#include <string>

#include "eval/inputs.h"

namespace rigc::eval {

// Whether the file's extension is a RAW format's (CR2, CR3, NEF, ARW, DNG, ORF, RW2, RAF, PEF).
bool is_raw_photo(const std::filesystem::path& path);

// Develops `raw` into the 8-bit sRGB JPEG `to` (with the RAW's EXIF), unless `to` is already
// newer than `raw`; *cached says which. False with `error` when the RAW cannot be read.
bool develop_raw(const std::filesystem::path& raw, const std::filesystem::path& to, bool* cached,
                 std::string* error);

// When `images` holds RAW files: develops them into OUT/developed/<stem>.jpg, links the other
// photos there (a JPEG beside a RAW of the same stem, as RAW + JPEG shooting leaves, is left
// out: the RAW is the photo) and makes that folder the image set. False with `error` when a RAW
// cannot be developed (the input's fault).
bool develop_raw_photos(ImageSet& images, const std::filesystem::path& out, std::ostream& log,
                        bool quiet, std::string* error);

}  // namespace rigc::eval
