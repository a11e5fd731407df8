// The cameras of a folder of photos, from their EXIF: make and model name one of RigC's body
// presets (compiler/presets.h), whose sensor size turns the focal length in millimetres into
// pixels, COLMAP's intrinsics prior. Photos of different bodies, focal lengths or sizes get a
// camera each. `--camera BODY,FOCAL` states the camera when the EXIF does not.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "compiler/presets.h"
#include "eval/inputs.h"

namespace rigc::eval {

// What a photo's EXIF says about its camera and when it was taken ("" / 0 when absent).
struct PhotoExif {
  std::string make, model;
  double focal_mm = 0;
  double focal_35mm = 0;  // Exif:FocalLengthIn35mmFilm
  std::string taken;      // DateTimeOriginal (+ sub-seconds), sortable
};
PhotoExif read_photo_exif(const std::filesystem::path& path);

// Whether `mm` can be a lens's focal length: finite, 1..5000 mm. EXIF's 50/0 reads as inf, and
// 1e9 mm is written as a rational of 1/2^31.
bool is_focal_length_mm(double mm);

// `--camera canon-6d,50mm`: a body preset and a focal length.
struct CameraStatement {
  BodyPreset body;
  double focal_mm = 0;
};
std::optional<CameraStatement> parse_camera_statement(const std::string& text, std::string* error);

// The body preset whose EXIF make and model these are (case and spaces aside).
std::optional<BodyPreset> preset_for_exif(const std::string& make, const std::string& model);

// Focal length in pixels of an image `width` x `height` taken with `body` at `focal_mm`: the
// image's long side spans the sensor's long side.
double focal_length_px(const BodyPreset& body, double focal_mm, int width, int height);

// One camera of the photos: its prior and the photos taken with it.
struct PhotoCamera {
  std::string label;          // "Canon EOS 6D, 50 mm, 821 x 547"
  std::string source;         // where the focal length comes from
  double focal_px = 0;        // 0: unknown (COLMAP guesses and refines it)
  bool sensor_known = false;  // from a body preset's sensor size: kept fixed in the adjustment
  int width = 0, height = 0;
  std::vector<std::string> images;
  nlohmann::json to_json() const;
};

// The cameras of `images` (a statement, when given, is every photo's camera). nullopt with
// `error` when the statement does not parse.
std::optional<std::vector<PhotoCamera>> photo_cameras(const ImageSet& images,
                                                      const std::string& statement,
                                                      std::string* error);

}  // namespace rigc::eval

namespace rigc::eval {

// The photos in the order they were taken: by EXIF time when every photo has a distinct one,
// else by file name (a camera numbers its files in order). `basis` says which.
std::vector<std::string> capture_order(const ImageSet& images, std::string* basis);

}  // namespace rigc::eval
