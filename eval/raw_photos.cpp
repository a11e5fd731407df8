#include "eval/raw_photos.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <fmt/format.h>

#include <algorithm>
#include <set>

#include "dslr/image_io.h"
#include "io/input_files.h"

namespace rigc::eval {

namespace fs = std::filesystem;

bool is_raw_photo(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  static const std::set<std::string> raw = {".cr2", ".cr3", ".nef", ".arw", ".dng",
                                            ".orf", ".rw2", ".raf", ".pef"};
  return raw.count(ext) > 0;
}

namespace {

// The RAW read as the camera saw it: LibRaw with the white balance of the file, sRGB primaries,
// no automatic brightening (the exposure is the photographer's).
bool read_raw(const fs::path& raw, OIIO::ImageBuf& image, std::string* error) {
  OIIO::ImageSpec config;
  config.attribute("raw:use_camera_wb", 1);
  config.attribute("raw:use_camera_matrix", 1);
  config.attribute("raw:ColorSpace", "sRGB");
  config.attribute("raw:auto_bright", 0);
  image = OIIO::ImageBuf(raw.string(), 0, 0, nullptr, &config);
  if (!image.read(0, 0, true, OIIO::TypeDesc::FLOAT)) {
    *error = fmt::format("cannot develop the RAW photo {}: {}", raw.string(), image.geterror());
    return false;
  }
  return true;
}

}  // namespace

bool develop_raw(const fs::path& raw, const fs::path& to, bool* cached, std::string* error) {
  std::error_code ec;
  *cached = fs::exists(to, ec) && fs::last_write_time(to, ec) > fs::last_write_time(raw, ec);
  if (*cached) return true;
  OIIO::ImageBuf linear;
  if (!read_raw(raw, linear, error)) return false;
  // LibRaw hands over linear values: encode them with sRGB's transfer, as the preview does.
  const std::string space = linear.spec().get_string_attribute("oiio:ColorSpace", "linear");
  OIIO::ImageBuf srgb = OIIO::ImageBufAlgo::colorconvert(linear, space, "sRGB");
  if (srgb.has_error()) {
    *error = fmt::format("cannot develop {}: {}", raw.string(), srgb.geterror());
    return false;
  }
  OIIO::ImageSpec& spec = srgb.specmod();
  spec.attribute("oiio:ColorSpace", "sRGB");
  spec.attribute("Compression", "jpeg:95");
  return dslr::write_image_buffer(to, srgb, error);
}

bool develop_raw_photos(ImageSet& images, const fs::path& out, std::ostream& log, bool quiet,
                        std::string* error) {
  std::set<std::string> raw_stems;
  for (const auto& name : images.names) {
    if (is_raw_photo(name)) raw_stems.insert(fs::path(name).stem().string());
  }
  if (raw_stems.empty()) return true;
  const fs::path dir = out / "developed";
  std::error_code ec;
  fs::create_directories(dir, ec);
  ImageSet developed;
  developed.dir = dir;
  int fresh = 0;
  for (const auto& name : images.names) {
    const std::string stem = fs::path(name).stem().string();
    const std::string new_name = is_raw_photo(name) ? stem + ".jpg" : name;
    if (raw_stems.count(stem) && !is_raw_photo(name)) continue;  // the camera's JPEG of a RAW
    // Photos in OUT/developed itself: neither replaced by a link to themselves nor developed over
    // (a link there is this folder's own, from an earlier run).
    const bool own_link = fs::is_symlink(fs::symlink_status(dir / new_name, ec));
    if (const auto input = own_link ? std::nullopt : protected_input_at(dir / new_name)) {
      *error = fmt::format(
          "will not write {}: it is {}, an input of this command; choose "
          "another output folder",
          (dir / new_name).string(), *input);
      return false;
    }
    if (is_raw_photo(name)) {
      bool cached = false;
      if (!develop_raw(images.dir / name, dir / new_name, &cached, error)) return false;
      fresh += !cached;
    } else {
      fs::remove(dir / name, ec);
      fs::create_symlink(fs::absolute(images.dir / name), dir / name, ec);
      if (images.wider_than_eight_bit.count(name)) developed.wider_than_eight_bit.insert(name);
    }
    auto input = OIIO::ImageInput::open((dir / new_name).string());
    if (!input) {
      *error = fmt::format("cannot read {}: {}", (dir / new_name).string(), OIIO::geterror());
      return false;
    }
    developed.size[new_name] = {input->spec().width, input->spec().height};
    developed.names.push_back(new_name);
  }
  std::sort(developed.names.begin(), developed.names.end());
  if (!quiet) {
    log << fmt::format("rigc eval: {} RAW photos developed into {} ({} from the cache)\n",
                       raw_stems.size(), dir.string(), raw_stems.size() - fresh);
  }
  images = std::move(developed);
  return true;
}

}  // namespace rigc::eval
