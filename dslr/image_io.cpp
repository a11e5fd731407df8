#include "dslr/image_io.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <system_error>

#include "dslr/buffer_pool.h"
#include "dslr/mask_png.h"
#include "io/atomic_file.h"

namespace rigc::dslr {

namespace fs = std::filesystem;

namespace {

void set_error(std::string* error, const std::string& message) {
  if (error != nullptr) *error = message;
}

}  // namespace

bool write_pixels(const fs::path& path, const OIIO::ImageSpec& spec, const void* pixels,
                  std::string* error) {
  OIIO::Filesystem::IOVecOutput memory;
  auto out = OIIO::ImageOutput::create(path.string(), &memory);
  if (!out) {
    set_error(error, "cannot write " + path.string() + ": " + OIIO::geterror());
    return false;
  }
  if (!out->supports("ioproxy")) {
    set_error(error, "cannot write " + path.string() + ": the " + out->format_name() +
                         " writer cannot encode to memory; name a .jpg, .png or .tif file");
    return false;
  }
  auto fail = [&](const std::string& why) {
    set_error(error, "cannot write " + path.string() + ": " + why);
    return false;
  };
  if (!out->open(path.string(), spec)) return fail(out->geterror());
  if (!out->write_image(spec.format, pixels)) return fail(out->geterror());
  if (!out->close()) return fail(out->geterror());
  out.reset();
  const std::vector<unsigned char>& bytes = memory.buffer();
  return write_file_atomically(
      path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), error);
}

bool write_image_buffer(const fs::path& path, const OIIO::ImageBuf& image, std::string* error) {
  OIIO::ImageSpec spec = image.spec();
  spec.set_format(OIIO::TypeDesc::UINT8);
  spec.erase_attribute("oiio:BitsPerSample");  // a 16-bit source's depth
  std::vector<std::uint8_t> pixels(spec.image_bytes());
  if (!image.get_pixels(image.roi(), OIIO::TypeDesc::UINT8, pixels.data())) {
    set_error(error, "cannot write " + path.string() + ": " + image.geterror());
    return false;
  }
  return write_pixels(path, spec, pixels.data(), error);
}

namespace {

// ".jpg" for "shot.JPG": the file type the name asks for.
std::string lowercase_extension(const fs::path& path) {
  std::string extension = path.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension;
}

// EXIF's ASCII tags (Make, Model) hold 7-bit text: each UTF-8 character outside it, and each
// control character, becomes one '?' (camera names come from the user's scene).
std::string exif_ascii(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x80 && byte < 0xC0) continue;  // a UTF-8 continuation byte
    out += byte >= 0x20 && byte < 0x7F ? c : '?';
  }
  return out;
}

}  // namespace

bool write_image(const fs::path& path, const DevelopResult& result, const ir::Camera& camera,
                 std::string* error) {
  const std::size_t values = static_cast<std::size_t>(result.width) * result.height * 3;
  const bool bytes_only = result.encoded.empty() && result.bits == 8;
  if (result.width <= 0 || result.height <= 0 ||
      (bytes_only ? result.encoded_bytes.size() : result.encoded.size()) != values) {
    set_error(error, "cannot write " + path.string() + ": the image is empty or malformed");
    return false;
  }
  const std::string extension = lowercase_extension(path);
  const bool jpeg = extension == ".jpg" || extension == ".jpeg";
  const bool eight_bits = jpeg || result.bits == 8;

  OIIO::ImageSpec spec(result.width, result.height, 3,
                       eight_bits ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16);
  spec.attribute("oiio:ColorSpace", "sRGB");
  if (jpeg) {
    spec.attribute("Compression",
                   "jpeg:" + std::to_string(std::clamp(camera.jpeg_quality, 1, 100)));
  }
  spec.attribute("Make", exif_ascii(camera.make));
  spec.attribute("Model", exif_ascii(camera.model));
  spec.attribute("Software", "RigC " RIGC_VERSION);
  const double focal_mm = camera.focal_length_m * 1000;
  spec.attribute("Exif:FocalLength", static_cast<float>(focal_mm));
  spec.attribute("FNumber", static_cast<float>(camera.aperture_f_number));
  spec.attribute("ExposureTime", static_cast<float>(camera.shutter_s));
  spec.attribute("Exif:PhotographicSensitivity", static_cast<int>(std::lround(camera.iso)));
  const double diagonal_mm =
      std::hypot(camera.sensor_width_m, camera.sensor_height_m) * 1000;  // 35 mm film: 43.27 mm
  if (diagonal_mm > 0) {
    spec.attribute("Exif:FocalLengthIn35mmFilm",
                   static_cast<int>(std::lround(focal_mm * 43.2666 / diagonal_mm)));
  }
  if (camera.sensor_width_m > 0 && camera.sensor_height_m > 0) {
    spec.attribute("Exif:FocalPlaneXResolution",
                   static_cast<float>(result.width / (camera.sensor_width_m * 100)));
    spec.attribute("Exif:FocalPlaneYResolution",
                   static_cast<float>(result.height / (camera.sensor_height_m * 100)));
    spec.attribute("Exif:FocalPlaneResolutionUnit", 3);  // centimetres
  }

  if (bytes_only) return write_pixels(path, spec, result.encoded_bytes.data(), error);
  if (eight_bits) {
    std::vector<std::uint8_t> pixels = take_bytes(values);  // every value is written
    // Plain pointers and one loop per case: stores through a byte pointer may alias anything,
    // so indexing the vectors reloads their data pointers on every value and nothing vectorises.
    const std::uint16_t* codes = result.encoded.data();
    std::uint8_t* bytes = pixels.data();
    if (result.bits == 8) {
      for (std::size_t i = 0; i < values; ++i) bytes[i] = static_cast<std::uint8_t>(codes[i]);
    } else {
      for (std::size_t i = 0; i < values; ++i) {
        bytes[i] = static_cast<std::uint8_t>((codes[i] * 255u + 32767u) / 65535u);
      }
    }
    const bool written = write_pixels(path, spec, pixels.data(), error);
    recycle(std::move(pixels));
    return written;
  }
  return write_pixels(path, spec, result.encoded.data(), error);
}

bool write_mask(const fs::path& path, ImageView<const std::uint8_t> mask, std::string* error) {
  if (mask.empty() || mask.channels != 1) {
    set_error(error, "cannot write " + path.string() + ": the mask is empty or malformed");
    return false;
  }
  if (lowercase_extension(path) == ".png") {
    // Encoded by runs: much faster than zlib on a mask (see mask_png.h).
    return write_file_atomically(path, encode_mask_png(mask), error);
  }
  // Any other format OpenImageIO writes (the backends name masks .png).
  return write_pixels(path, OIIO::ImageSpec(mask.width, mask.height, 1, OIIO::TypeDesc::UINT8),
                      mask.values, error);
}

}  // namespace rigc::dslr
