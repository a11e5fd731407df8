#include "eval/photo_camera.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <map>
#include <tuple>

namespace rigc::eval {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Lower case, runs of spaces as one, no spaces at the ends: EXIF text is padded and cased freely.
std::string normalised(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '\0') break;
    if (std::isspace(static_cast<unsigned char>(c))) {
      if (!out.empty() && out.back() != ' ') out += ' ';
    } else {
      out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
  }
  if (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

}  // namespace

PhotoExif read_photo_exif(const fs::path& path) {
  PhotoExif exif;
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) {
    OIIO::geterror();  // clear it: the headers were checked before
    return exif;
  }
  const OIIO::ImageSpec& spec = in->spec();
  exif.make = spec.get_string_attribute("Make");
  exif.model = spec.get_string_attribute("Model");
  exif.focal_mm = spec.get_float_attribute("Exif:FocalLength", 0.0f);
  exif.focal_35mm = spec.get_float_attribute("Exif:FocalLengthIn35mmFilm", 0.0f);
  std::string taken = spec.get_string_attribute("Exif:DateTimeOriginal");
  if (taken.empty()) taken = spec.get_string_attribute("DateTime");
  if (!taken.empty()) {
    taken += "." + std::string(spec.get_string_attribute("Exif:SubsecTimeOriginal", "0"));
  }
  exif.taken = taken;
  return exif;
}

bool is_focal_length_mm(double mm) {
  // A phone's lens is about 2 mm; the longest lenses made about 5000 mm.
  constexpr double kShortestMm = 1, kLongestMm = 5000;
  return std::isfinite(mm) && mm >= kShortestMm && mm <= kLongestMm;
}

std::optional<CameraStatement> parse_camera_statement(const std::string& text, std::string* error) {
  const auto comma = text.find(',');
  auto refuse = [&](const std::string& why) {
    *error = fmt::format("--camera '{}': {}", text, why);
    return std::nullopt;
  };
  if (comma == std::string::npos) return refuse("give BODY,FOCAL, e.g. canon-6d,50mm");
  const std::string body = text.substr(0, comma);
  std::string focal = text.substr(comma + 1);
  if (focal.size() > 2 && focal.substr(focal.size() - 2) == "mm") focal.resize(focal.size() - 2);
  CameraStatement s;
  const auto preset = find_body_preset(body);
  if (!preset) {
    std::string known;
    for (const auto& p : body_presets()) known += (known.empty() ? "" : ", ") + p.name;
    return refuse(fmt::format("unknown body '{}' (known: {})", body, known));
  }
  s.body = *preset;
  const auto [end, ec] = std::from_chars(focal.data(), focal.data() + focal.size(), s.focal_mm);
  if (ec != std::errc() || end != focal.data() + focal.size() || !is_focal_length_mm(s.focal_mm)) {
    return refuse(fmt::format("'{}' is no focal length in mm (e.g. 50mm)", text.substr(comma + 1)));
  }
  return s;
}

std::optional<BodyPreset> preset_for_exif(const std::string& make, const std::string& model) {
  const std::string m = normalised(model);
  if (m.empty()) return std::nullopt;
  for (const auto& p : body_presets()) {
    // LibRaw drops the make from the model ("EOS 6D"); cameras write it in both.
    const bool model_matches =
        normalised(p.model) == m || normalised(p.model) == normalised(make + " " + model);
    if (model_matches && (make.empty() || normalised(p.make) == normalised(make))) {
      return p;
    }
  }
  return std::nullopt;
}

double focal_length_px(const BodyPreset& body, double focal_mm, int width, int height) {
  const double sensor_long_mm = std::max(body.sensor_width_m, body.sensor_height_m) * 1000;
  return focal_mm / sensor_long_mm * std::max(width, height);
}

json PhotoCamera::to_json() const {
  return {{"camera", label},
          {"focal_length_px", focal_px > 0 ? json(focal_px) : json(nullptr)},
          {"source", source},
          {"fixed_in_adjustment", sensor_known},
          {"images", images.size()}};
}

namespace {

// One photo's camera (its images left empty).
PhotoCamera camera_of(const PhotoExif& exif, const std::optional<CameraStatement>& statement,
                      std::pair<int, int> size) {
  PhotoCamera c;
  c.width = size.first;
  c.height = size.second;
  std::optional<BodyPreset> body;
  double focal_mm = 0;
  // Why the EXIF's body preset cannot give the focal length (50/0 read as inf, 0, 1e9 mm).
  std::string unusable;
  if (statement) {
    body = statement->body;
    focal_mm = statement->focal_mm;
    c.source = fmt::format("--camera: body preset {}, {} mm", body->name, focal_mm);
  } else if ((body = preset_for_exif(exif.make, exif.model))) {
    focal_mm = exif.focal_mm;
    c.source = fmt::format("EXIF: {} {} (body preset {}), {} mm", exif.make, exif.model, body->name,
                           focal_mm);
    if (!is_focal_length_mm(focal_mm)) {
      unusable = fmt::format(
          "{} {} is body preset {}, but its EXIF focal length ({} mm) is no "
          "focal length",
          exif.make, exif.model, body->name, exif.focal_mm);
      body.reset();
    }
  }
  if (body) {
    c.focal_px = focal_length_px(*body, focal_mm, c.width, c.height);
    c.sensor_known = true;
    c.label = fmt::format("{}, {} mm, {} x {}", body->model, focal_mm, c.width, c.height);
  } else if (is_focal_length_mm(exif.focal_35mm)) {
    // A 35 mm film frame is 36 mm wide.
    c.focal_px = exif.focal_35mm / 36.0 * std::max(c.width, c.height);
    c.source = fmt::format(
        "EXIF: 35 mm equivalent {} mm ({})", exif.focal_35mm,
        unusable.empty() ? exif.make + " " + exif.model + " is no body preset" : unusable);
    c.label = fmt::format("{} {}, {} mm (35 mm eq.), {} x {}", exif.make, exif.model,
                          exif.focal_35mm, c.width, c.height);
  } else {
    c.source = exif.model.empty()
                   ? "none: no EXIF camera (COLMAP guesses; --camera states it)"
                   : fmt::format(
                         "none: {} and its EXIF has no 35 mm focal length (--camera "
                         "states it)",
                         unusable.empty() ? exif.make + " " + exif.model + " is no body preset"
                                          : unusable);
    c.label = fmt::format("unknown camera, {} x {}", c.width, c.height);
  }
  return c;
}

}  // namespace

std::optional<std::vector<PhotoCamera>> photo_cameras(const ImageSet& images,
                                                      const std::string& statement_text,
                                                      std::string* error) {
  std::optional<CameraStatement> statement;
  if (!statement_text.empty()) {
    statement = parse_camera_statement(statement_text, error);
    if (!statement) return std::nullopt;
  }
  std::vector<PhotoCamera> cameras;
  std::map<std::tuple<std::string, std::string>, std::size_t> index;  // label, source
  for (const auto& name : images.names) {
    PhotoCamera c = camera_of(read_photo_exif(images.dir / name), statement, images.size.at(name));
    const auto key = std::tuple{c.label, c.source};
    auto it = index.find(key);
    if (it == index.end()) {
      it = index.emplace(key, cameras.size()).first;
      cameras.push_back(std::move(c));
    }
    cameras[it->second].images.push_back(name);
  }
  return cameras;
}

}  // namespace rigc::eval

namespace rigc::eval {

std::vector<std::string> capture_order(const ImageSet& images, std::string* basis) {
  std::vector<std::pair<std::string, std::string>> timed;  // time, name
  for (const auto& name : images.names) {
    timed.emplace_back(read_photo_exif(images.dir / name).taken, name);
  }
  std::sort(timed.begin(), timed.end());
  const bool all_timed =
      std::none_of(timed.begin(), timed.end(), [](const auto& t) { return t.first.empty(); });
  const bool distinct =
      std::adjacent_find(timed.begin(), timed.end(), [](const auto& a, const auto& b) {
        return a.first == b.first;
      }) == timed.end();
  if (!all_timed || !distinct) {
    *basis = "file names";
    return images.names;
  }
  *basis = "EXIF time taken";
  std::vector<std::string> order;
  for (const auto& t : timed) order.push_back(t.second);
  return order;
}

}  // namespace rigc::eval
