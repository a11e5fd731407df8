#include "compiler/check.h"

#include <fmt/format.h>
#include <yaml-cpp/eventhandler.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <tuple>

#include "assets/primitives.h"
#include "compiler/limits.h"
#include "compiler/presets.h"
#include "compiler/units.h"
#include "compiler/yaml_limits.h"
#include "io/file_status.h"
#include "ir/utf8_text.h"

namespace rigc {
namespace {

namespace fs = std::filesystem;
using spec::Target;

// Why `name` cannot be one folder of a path, or empty when it can: the scene's name is the
// default run folder's parent (out/<name>/<backend>), so "/tmp/x" or "../../x" would put runs
// elsewhere.
std::string folder_name_problem(const std::string& name) {
  if (name.empty()) return "it is empty";
  if (name.size() > limits::kSceneName.max) {
    return fmt::format("it is longer than {} bytes", limits::kSceneName.max);
  }
  if (name == "." || name == "..") return "'.' and '..' are not folder names";
  for (const unsigned char c : name) {
    if (c == '/' || c == '\\') return "it holds a slash";
    if (c < 0x20 || c == 0x7F) return "it holds a control character";
  }
  // C1 controls (U+0080..U+009F, UTF-8 C2 80..C2 9F) and the bidirectional controls (U+200E,
  // U+200F, U+202A..U+202E, U+2066..U+2069), which make a folder name display as another.
  for (std::size_t i = 0; i + 1 < name.size(); ++i) {
    const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(name[k]); };
    if (byte(i) == 0xC2 && byte(i + 1) >= 0x80 && byte(i + 1) <= 0x9F) {
      return "it holds a control character";
    }
    if (i + 2 < name.size() && byte(i) == 0xE2) {
      const unsigned second = byte(i + 1), third = byte(i + 2);
      if ((second == 0x80 &&
           (third == 0x8E || third == 0x8F || (third >= 0xAA && third <= 0xAE))) ||
          (second == 0x81 && third >= 0xA6 && third <= 0xA9)) {
        return "it holds a bidirectional text control";
      }
    }
  }
  return {};
}

std::string comma_list(const std::vector<std::string>& words) {
  std::string list;
  for (const auto& word : words) list += (list.empty() ? "" : ", ") + word;
  return list;
}

// "; did you mean 'x'?" when one of `known` is close to `word`, else `otherwise`.
std::string did_you_mean(const std::string& word, const std::vector<std::string>& known,
                         const std::string& otherwise) {
  const std::string suggestion = closest_match(word, known);
  return suggestion.empty() ? otherwise : fmt::format("; did you mean '{}'?", suggestion);
}

// Walks the YAML tree with the diagnostics engine at hand. Each reader reports its own errors and
// returns nullopt, so checking goes on and every error of the file is reported in one run.
class Checker {
 public:
  Checker(const std::string& file, const std::string& base_dir, DiagnosticEngine& diag)
      : file_(file), base_dir_(base_dir), diag_(diag) {}

  std::optional<spec::SceneSpec> run(const YAML::Node& root);

 private:
  SourceLoc loc(const YAML::Node& node) const {
    const YAML::Mark mark = node.Mark();
    if (mark.line < 0) return {file_, 0, 0};
    return {file_, mark.line + 1, mark.column + 1};
  }
  void error(const YAML::Node& node, std::string message) { diag_.error(loc(node), message); }

  bool expect_map(const YAML::Node& node, const std::string& what) {
    if (node.IsMap()) return true;
    error(node, fmt::format("{} must be a mapping of keys to values", what));
    return false;
  }

  // Reports keys not in `allowed`, with a suggestion; returns false if there were any.
  bool check_keys(const YAML::Node& map, const std::vector<std::string>& allowed,
                  const std::string& context) {
    bool ok = true;
    // yaml-cpp keeps a repeated key's first value and drops the rest without a word (`iso: 200,
    // iso: 400` would be ISO 200), so repeats are errors.
    std::map<std::string, int> first_line;
    for (auto it = map.begin(); it != map.end(); ++it) {
      if (!it->first.IsScalar()) {
        error(it->first, fmt::format("keys in {} must be plain names", context));
        ok = false;
        continue;
      }
      const std::string key = it->first.Scalar();
      if (auto [seen, fresh] = first_line.try_emplace(key, loc(it->first).line); !fresh) {
        error(it->first, fmt::format("duplicate key '{}' in {} (first given on line {})", key,
                                     context, seen->second));
        ok = false;
        continue;
      }
      if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
      error(it->first,
            fmt::format("unknown key '{}' in {}", key, context) +
                did_you_mean(key, allowed,
                             fmt::format(" (expected one of: {})", comma_list(allowed))));
      ok = false;
    }
    return ok;
  }

  // True if `key` is absent and no misspelt key stands for it (that one was reported already).
  bool lacks(const YAML::Node& map, const std::string& key) {
    if (map[key]) return false;
    for (auto it = map.begin(); it != map.end(); ++it) {
      if (it->first.IsScalar() && closest_match(it->first.Scalar(), {key}) == key) return false;
    }
    return true;
  }

  std::optional<std::string> scalar(const YAML::Node& node, const std::string& what) {
    if (node.IsScalar()) return node.Scalar();
    error(node, fmt::format("{} must be a single value", what));
    return std::nullopt;
  }

  std::optional<double> quantity(const YAML::Node& node, QuantityKind kind,
                                 const std::string& what) {
    auto text = scalar(node, what);
    if (!text) return std::nullopt;
    QuantityParse parsed = parse_quantity(*text, kind);
    if (!parsed.value) error(node, fmt::format("{}: {}", what, parsed.error));
    return parsed.value;
  }

  std::optional<double> quantity(const YAML::Node& node, const std::string& what,
                                 const limits::Quantity& limit) {
    const std::optional<double> value = quantity(node, limit.kind, what);
    if (!value) return std::nullopt;
    const bool below = limit.min_exclusive ? *value <= limit.min : *value < limit.min;
    if (below || *value > limit.max) {
      error(node, fmt::format("{} {} is outside {}..{}", what, format_quantity(*value, limit.kind),
                              format_quantity(limit.min, limit.kind),
                              format_quantity(limit.max, limit.kind)));
      return std::nullopt;
    }
    return value;
  }

  // Sets `out` from `map[key]` if it is given and within `limit`.
  void read(const YAML::Node& map, const char* key, const std::string& what,
            const limits::Quantity& limit, double& out) {
    if (!map[key]) return;
    if (auto value = quantity(map[key], what, limit)) out = *value;
  }

  std::optional<int> integer(const YAML::Node& node, const std::string& what,
                             const limits::Integer& limit) {
    auto text = scalar(node, what);
    if (!text) return std::nullopt;
    long value = 0;
    try {
      size_t pos = 0;
      value = std::stol(*text, &pos);
      if (pos != text->size()) throw std::invalid_argument("trailing");
    } catch (...) {
      error(node, fmt::format("{} must be a whole number, got '{}'", what, *text));
      return std::nullopt;
    }
    if (value < limit.min || value > limit.max) {
      error(node, fmt::format("{} {} is outside {}..{}", what, value, limit.min, limit.max));
      return std::nullopt;
    }
    return static_cast<int>(value);
  }

  template <typename Int>
  void read(const YAML::Node& map, const char* key, const std::string& what,
            const limits::Integer& limit, Int& out) {
    if (!map[key]) return;
    if (auto value = integer(map[key], what, limit)) out = static_cast<Int>(*value);
  }

  std::optional<bool> boolean(const YAML::Node& node, const std::string& what) {
    auto text = scalar(node, what);
    if (!text) return std::nullopt;
    if (*text == "true" || *text == "on" || *text == "yes") return true;
    if (*text == "false" || *text == "off" || *text == "no") return false;
    error(node, fmt::format("{} must be true or false, got '{}'", what, *text));
    return std::nullopt;
  }

  // [x, y, z], each read by `read_one`.
  template <typename ReadOne>
  std::optional<ir::Vec3> vec3_of(const YAML::Node& node, const std::string& what,
                                  ReadOne read_one) {
    if (!node.IsSequence() || node.size() != 3) {
      error(node, fmt::format("{} must be a list of three values [x, y, z]", what));
      return std::nullopt;
    }
    ir::Vec3 result;
    bool ok = true;
    for (int i = 0; i < 3; ++i) {
      auto v = read_one(node[i]);
      if (v)
        result[i] = *v;
      else
        ok = false;
    }
    if (!ok) return std::nullopt;
    return result;
  }
  std::optional<ir::Vec3> vec3(const YAML::Node& node, QuantityKind kind, const std::string& what) {
    return vec3_of(node, what, [&](const YAML::Node& n) { return quantity(n, kind, what); });
  }
  std::optional<ir::Vec3> vec3(const YAML::Node& node, const std::string& what,
                               const limits::Quantity& limit) {
    return vec3_of(node, what, [&](const YAML::Node& n) { return quantity(n, what, limit); });
  }

  std::optional<ir::Vec3> color(const YAML::Node& node, const std::string& what,
                                const limits::Quantity& limit) {
    if (!node.IsSequence() || node.size() != 3) {
      error(node, fmt::format("{} must be a list of three linear RGB values in 0..1", what));
      return std::nullopt;
    }
    return vec3(node, what, limit);
  }
  void read_color(const YAML::Node& map, const std::string& what, const limits::Quantity& limit,
                  ir::Vec3& out) {
    if (!map["color"]) return;
    if (auto c = color(map["color"], what, limit)) out = *c;
  }

  std::optional<Target> target(const YAML::Node& node, const std::string& what,
                               const limits::Quantity& limit) {
    Target result;
    result.loc = loc(node);
    if (node.IsScalar()) {
      if (node.Scalar() == "object") return result;
      error(node, fmt::format("{} must be 'object' or a position [x, y, z], got '{}'", what,
                              node.Scalar()));
      return std::nullopt;
    }
    auto point = vec3(node, what, limit);
    if (!point) return std::nullopt;
    result.object = false;
    result.point = *point;
    return result;
  }

  // A non-zero direction, normalised; nullopt (reported) if zero.
  std::optional<ir::Vec3> direction(const YAML::Node& node, const std::string& what,
                                    const std::string& zero_message) {
    auto d = vec3(node, QuantityKind::kNumber, what);
    if (!d) return std::nullopt;
    // stableNorm: norm() overflows to inf on [1e200, 0, 0], and normalized() gives zero.
    if (d->stableNorm() < 1e-9) {
      error(node, zero_message);
      return std::nullopt;
    }
    return d->stableNormalized();
  }

  void read_name(const YAML::Node& root, spec::SceneSpec& scene);
  void read_object(const YAML::Node& node, spec::SceneSpec& scene);
  void read_mesh(const YAML::Node& node, spec::ObjectSpec& object);
  void read_primitive(const YAML::Node& primitive, spec::ObjectSpec& object);
  void read_up_axis(const YAML::Node& node, spec::ObjectSpec& object);
  void read_fit(const YAML::Node& fit, spec::ObjectSpec& object);
  void read_scale(const YAML::Node& node, spec::ObjectSpec& object);
  void read_surface(const YAML::Node& node, spec::ObjectSpec& object);
  void read_studio(const YAML::Node& node, spec::SceneSpec& scene);
  void read_turntable(const YAML::Node& table, ir::Turntable& turntable);
  void read_backdrop(const YAML::Node& backdrop, spec::SceneSpec& scene);
  void read_lights(const YAML::Node& lights, spec::SceneSpec& scene);
  void read_light(const YAML::Node& node, spec::SceneSpec& scene);
  std::optional<ir::LightType> light_type(const YAML::Node& node);
  void read_light_source(const YAML::Node& node, const std::string& type, ir::Light& light);
  void read_light_aim(const YAML::Node& node, spec::LightSpec& light_spec);
  void read_light_shape(const YAML::Node& node, ir::Light& light);
  void read_camera(const YAML::Node& node, spec::SceneSpec& scene);
  void read_camera_kind(const YAML::Node& node, spec::SceneSpec& scene);
  void read_body(const YAML::Node& body, ir::Camera& camera);
  void read_sensor(const YAML::Node& sensor, ir::Camera& camera);
  void read_intrinsics(const YAML::Node& node, spec::SceneSpec& scene);
  std::optional<double> focal_length_px(const YAML::Node& node, const std::string& what,
                                        const limits::Quantity& limit);
  void read_principal_point(const YAML::Node& node, const char* key, int size_px, double& out);
  void size_intrinsics_camera(const YAML::Node& node, spec::SceneSpec& scene);
  void read_exif_text(const YAML::Node& node, ir::Camera& camera);
  void read_lens(const YAML::Node& lens, ir::Camera& camera, bool needs_focal_length);
  void read_lens_preset(const YAML::Node& lens, ir::Camera& camera);
  void check_lens_limits(const YAML::Node& node, spec::SceneSpec& scene);
  void read_distortion(const YAML::Node& distortion, ir::Camera& camera);
  void read_exposure(const YAML::Node& exposure, ir::Camera& camera);
  void read_focus(const YAML::Node& focus, spec::SceneSpec& scene);
  void read_white_balance(const YAML::Node& wb, ir::Camera& camera);
  void read_effects(const YAML::Node& effects, ir::Camera& camera);
  void read_output(const YAML::Node& output, ir::Camera& camera);
  void finish_camera(ir::Camera& camera, bool pixels_measured);
  void read_shots(const YAML::Node& node, spec::SceneSpec& scene);
  void read_coverage(const YAML::Node& node, spec::SceneSpec& scene);
  void read_turntable_shots(const YAML::Node& node, spec::ShotGroupSpec& group);
  void read_turntable_camera(const YAML::Node& camera, spec::TurntableCameraSpec& out);
  void read_orbit_shots(const YAML::Node& node, spec::ShotGroupSpec& group);
  void read_ring(const YAML::Node& node, spec::OrbitShotsSpec& orbit);
  void read_pose_shot(const YAML::Node& node, spec::ShotGroupSpec& group);
  void read_pose_aim(const YAML::Node& node, spec::PoseShotSpec& pose);
  std::optional<Eigen::Matrix3d> rotation(const YAML::Node& node);
  std::optional<Eigen::Matrix3d> rotation_matrix(const YAML::Node& node);
  std::optional<Eigen::Matrix3d> rotation_quaternion(const YAML::Node& node);

  std::string file_;
  std::string base_dir_;
  DiagnosticEngine& diag_;
  std::optional<LensPreset> lens_preset_;  // the camera's `lens: {preset: ...}`
};

std::optional<spec::SceneSpec> Checker::run(const YAML::Node& root) {
  spec::SceneSpec scene;
  scene.source_file = file_;
  scene.base_dir = base_dir_;
  scene.name = fs::path(file_).stem().string();
  if (!root.IsMap()) {
    diag_.error({file_, 1, 1},
                "a scene file must be a mapping with the keys rigc, object, camera "
                "and shots");
    return std::nullopt;
  }
  check_keys(root, {"rigc", "name", "object", "studio", "camera", "shots", "coverage"},
             "the scene");
  if (root["rigc"]) {
    read(root, "rigc", "language version 'rigc'", limits::kLanguageVersion, scene.version);
  } else {
    diag_.error({file_, 1, 1}, "missing 'rigc: 1' (the language version) at the top of the scene");
  }
  read_name(root, scene);
  if (root["object"]) {
    read_object(root["object"], scene);
  } else {
    diag_.error({file_, 1, 1}, "missing 'object': the thing to photograph");
  }
  if (root["studio"]) read_studio(root["studio"], scene);
  if (root["camera"]) {
    read_camera(root["camera"], scene);
  } else {
    diag_.error({file_, 1, 1}, "missing 'camera'");
  }
  if (root["shots"]) {
    read_shots(root["shots"], scene);
  } else {
    diag_.error({file_, 1, 1}, "missing 'shots': the list of photos to take");
  }
  if (root["coverage"]) read_coverage(root["coverage"], scene);
  if (diag_.has_errors()) return std::nullopt;
  return scene;
}

// The scene's name, or the file's if it gives none: either must be able to name a folder.
void Checker::read_name(const YAML::Node& root, spec::SceneSpec& scene) {
  if (root["name"]) {
    if (auto name = scalar(root["name"], "name")) {
      if (std::string problem = folder_name_problem(*name); !problem.empty()) {
        error(root["name"], fmt::format("the scene's name cannot name a folder ({}): runs go to "
                                        "out/<name>/ by default",
                                        problem));
      } else {
        scene.name = *name;
      }
    }
  } else if (std::string problem = folder_name_problem(scene.name); !problem.empty()) {
    diag_.error({file_, 1, 1}, fmt::format("the file's name cannot name a folder ({}); give the "
                                           "scene a 'name:'",
                                           problem));
  }
}

void Checker::read_coverage(const YAML::Node& node, spec::SceneSpec& scene) {
  namespace limit = limits::coverage;
  ir::CoverageSettings& coverage = scene.coverage;
  coverage.loc = loc(node);
  if (!expect_map(node, "coverage")) return;
  check_keys(node,
             {"min_pixels_per_mm2", "max_view_angle", "max_blur", "min_triangulation_angle",
              "min_signal", "max_signal", "min_overlap", "min_frame_fill"},
             "coverage");
  read(node, "min_pixels_per_mm2", "min_pixels_per_mm2", limit::kMinPixelsPerMm2,
       coverage.min_pixels_per_mm2);
  read(node, "max_view_angle", "max_view_angle", limit::kMaxViewAngle, coverage.max_view_angle_rad);
  read(node, "max_blur", "max_blur", limit::kMaxBlur, coverage.max_blur_px);
  read(node, "min_triangulation_angle", "min_triangulation_angle", limit::kMinTriangulationAngle,
       coverage.min_triangulation_angle_rad);
  read(node, "min_signal", "min_signal", limit::kMinSignal, coverage.min_signal);
  read(node, "max_signal", "max_signal", limit::kMaxSignal, coverage.max_signal);
  read(node, "min_overlap", "min_overlap", limit::kMinOverlap, coverage.min_overlap);
  read(node, "min_frame_fill", "min_frame_fill", limit::kMinFrameFill, coverage.min_frame_fill);
  if (coverage.min_signal >= coverage.max_signal) {
    error(node, "coverage min_signal must be below max_signal");
  }
}

void Checker::read_object(const YAML::Node& node, spec::SceneSpec& scene) {
  spec::ObjectSpec& object = scene.object;
  object.loc = loc(node);
  if (!expect_map(node, "object")) return;
  check_keys(node, {"mesh", "primitive", "up", "fit", "scale", "rotate", "translate", "surface"},
             "object");
  const bool has_mesh = static_cast<bool>(node["mesh"]);
  const bool has_primitive = static_cast<bool>(node["primitive"]);
  if (has_mesh == has_primitive) {
    error(node,
          "object needs exactly one of 'mesh' (a model file) or 'primitive' (sphere, box, "
          "cylinder, statue)");
  }
  if (has_mesh) read_mesh(node["mesh"], object);
  if (has_primitive) read_primitive(node["primitive"], object);
  if (node["up"]) read_up_axis(node["up"], object);
  if (node["fit"]) read_fit(node["fit"], object);
  if (node["scale"]) read_scale(node["scale"], object);
  if (node["rotate"]) {
    if (auto r = vec3(node["rotate"], "rotate", limits::object::kRotate)) object.rotate_rad = *r;
  }
  if (node["translate"]) {
    if (auto t = vec3(node["translate"], "translate", limits::object::kTranslate)) {
      object.translate = *t;
    }
  }
  if (node["surface"]) {
    object.surface_loc = loc(node["surface"]);
    read_surface(node["surface"], object);
  }
}

void Checker::read_mesh(const YAML::Node& node, spec::ObjectSpec& object) {
  auto path = scalar(node, "mesh");
  if (!path) return;
  object.mesh_path = spec::Located<std::string>{*path, loc(node)};
  fs::path resolved = fs::path(*path);
  if (resolved.is_relative()) resolved = fs::path(base_dir_) / resolved;
  object.mesh_path_resolved = resolved.lexically_normal().string();
  if (const std::string why = why_not_readable(resolved); !why.empty()) {
    error(node, fmt::format("mesh file '{}' {}", resolved.string(), why));
  } else {
    std::string ext = resolved.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    const std::set<std::string> formats = {".gltf", ".glb", ".obj", ".ply", ".stl"};
    if (!formats.count(ext)) {
      error(node, fmt::format("mesh '{}' has an unsupported format '{}' (use glTF/GLB, "
                              "OBJ, PLY or STL)",
                              *path, ext));
    }
  }
}

void Checker::read_primitive(const YAML::Node& primitive, spec::ObjectSpec& object) {
  // (yaml-cpp's Node::operator= writes through to the node, so pick the shape node once.)
  const YAML::Node shape = primitive.IsMap() ? primitive["shape"] : primitive;
  if (primitive.IsMap()) {
    check_keys(primitive, {"shape", "detail", "seed"}, "primitive");
    if (!shape) error(primitive, "primitive needs a 'shape' (sphere, box, cylinder, statue)");
    read(primitive, "detail", "primitive detail", limits::object::kPrimitiveDetail,
         object.primitive_detail);
    read(primitive, "seed", "primitive seed", limits::object::kPrimitiveSeed,
         object.primitive_seed);
  }
  if (!shape) return;
  auto name = scalar(shape, "primitive shape");
  if (!name) return;
  if (!primitive_from_name(*name)) {
    error(shape, fmt::format("unknown primitive '{}'", *name) +
                     did_you_mean(*name, primitive_names(),
                                  " (expected sphere, box, cylinder or statue)"));
  } else {
    object.primitive = spec::Located<std::string>{*name, loc(shape)};
  }
}

void Checker::read_up_axis(const YAML::Node& node, spec::ObjectSpec& object) {
  auto up = scalar(node, "up");
  if (!up) return;
  if (*up == "y" || *up == "+y" || *up == "z" || *up == "+z" || *up == "-y" || *up == "-z") {
    object.up_axis = up->back();
    object.up_negative = (*up)[0] == '-';
  } else {
    error(node, fmt::format("up must be y, z, -y or -z (the model file's up axis), got "
                            "'{}'",
                            *up));
  }
}

void Checker::read_fit(const YAML::Node& fit, spec::ObjectSpec& object) {
  if (!expect_map(fit, "fit")) return;
  check_keys(fit, {"height", "width", "size"}, "fit");
  if (fit.size() != 1) error(fit, "fit takes one of height, width or size");
  auto read_one = [&](const char* key, const limits::Quantity& limit,
                      std::optional<spec::Located<double>>& out) {
    if (!fit[key]) return;
    if (auto v = quantity(fit[key], fmt::format("fit {}", key), limit)) {
      out = spec::Located<double>{*v, loc(fit[key])};
    }
  };
  read_one("height", limits::object::kFitHeight, object.fit_height);
  read_one("width", limits::object::kFitWidth, object.fit_width);
  read_one("size", limits::object::kFitSize, object.fit_size);
}

// One factor, or one per axis.
void Checker::read_scale(const YAML::Node& node, spec::ObjectSpec& object) {
  if (node.IsSequence()) {
    if (auto s = vec3(node, "scale", limits::object::kScale)) object.scale = *s;
  } else if (auto s = quantity(node, "scale", limits::object::kScale)) {
    object.scale = ir::Vec3::Constant(*s);
  }
}

void Checker::read_surface(const YAML::Node& node, spec::ObjectSpec& object) {
  namespace limit = limits::object;
  if (!expect_map(node, "surface")) return;
  check_keys(node, {"pattern", "scale", "contrast", "seed", "color", "roughness", "metallic"},
             "surface");
  object.pattern.kind = ir::PatternKind::kSpeckle;
  if (node["pattern"]) {
    if (auto name = scalar(node["pattern"], "pattern")) {
      const std::vector<std::string> names = {"none", "speckle", "noise", "checker"};
      if (*name == "none")
        object.pattern.kind = ir::PatternKind::kNone;
      else if (*name == "speckle")
        object.pattern.kind = ir::PatternKind::kSpeckle;
      else if (*name == "noise")
        object.pattern.kind = ir::PatternKind::kNoise;
      else if (*name == "checker")
        object.pattern.kind = ir::PatternKind::kChecker;
      else {
        error(node["pattern"],
              fmt::format("unknown pattern '{}'", *name) +
                  did_you_mean(*name, names, " (expected none, speckle, noise or checker)"));
      }
    }
  }
  read(node, "scale", "pattern scale", limit::kPatternScale, object.pattern.scale_m);
  read(node, "contrast", "contrast", limit::kPatternContrast, object.pattern.contrast);
  read(node, "seed", "pattern seed", limit::kPatternSeed, object.pattern.seed);
  if (node["color"]) object.surface_color = color(node["color"], "surface color", limit::kColor);
  if (node["roughness"]) {
    object.roughness = quantity(node["roughness"], "roughness", limit::kRoughness);
  }
  if (node["metallic"]) {
    object.metallic = quantity(node["metallic"], "metallic", limit::kMetallic);
  }
}

void Checker::read_studio(const YAML::Node& node, spec::SceneSpec& scene) {
  if (!expect_map(node, "studio")) return;
  check_keys(node, {"turntable", "backdrop", "lights", "ambient", "floor"}, "studio");
  ir::Studio& studio = scene.studio;
  if (const YAML::Node table = node["turntable"]) read_turntable(table, studio.turntable);
  if (const YAML::Node backdrop = node["backdrop"]) read_backdrop(backdrop, scene);
  if (const YAML::Node lights = node["lights"]) read_lights(lights, scene);
  read(node, "ambient", "ambient", limits::studio::kAmbient, studio.ambient_lx);
  if (const YAML::Node floor = node["floor"]) {
    if (expect_map(floor, "floor")) {
      check_keys(floor, {"color"}, "floor");
      read_color(floor, "floor color", limits::studio::kFloorColor, studio.floor_color);
    }
  }
}

void Checker::read_turntable(const YAML::Node& table, ir::Turntable& turntable) {
  namespace limit = limits::studio;
  turntable.loc = loc(table);
  if (!expect_map(table, "turntable")) return;
  check_keys(table, {"diameter", "height", "thickness", "color"}, "turntable");
  read(table, "diameter", "turntable diameter", limit::kTurntableDiameter, turntable.diameter_m);
  read(table, "height", "turntable height", limit::kTurntableHeight, turntable.height_m);
  read(table, "thickness", "turntable thickness", limit::kTurntableThickness,
       turntable.thickness_m);
  read_color(table, "turntable color", limit::kTurntableColor, turntable.color);
}

void Checker::read_backdrop(const YAML::Node& node, spec::SceneSpec& scene) {
  namespace limit = limits::studio;
  ir::Backdrop& backdrop = scene.studio.backdrop;
  backdrop.loc = loc(node);
  if (!expect_map(node, "backdrop")) return;
  check_keys(node, {"green_screen", "color", "distance", "width", "height"}, "backdrop");
  if (const YAML::Node green = node["green_screen"]) {
    if (green.IsMap()) {
      check_keys(green, {"color"}, "green_screen");
      backdrop.green_screen = true;
      read_color(green, "green screen color", limit::kGreenScreenColor, backdrop.color);
    } else if (auto on = boolean(green, "green_screen")) {
      backdrop.green_screen = *on;
    }
  }
  read_color(node, "backdrop color", limit::kBackdropColor, backdrop.color);
  if (node["distance"]) {
    if (auto v = quantity(node["distance"], "backdrop distance", limit::kBackdropDistance)) {
      backdrop.distance_m = *v;
      scene.backdrop_distance_set = true;
    }
  }
  read(node, "width", "backdrop width", limit::kBackdropWidth, backdrop.width_m);
  read(node, "height", "backdrop height", limit::kBackdropHeight, backdrop.height_m);
}

void Checker::read_lights(const YAML::Node& lights, spec::SceneSpec& scene) {
  if (!lights.IsSequence()) {
    error(lights,
          "lights must be a list, e.g. - {type: point, position: [1m, -1m, 1.5m], "
          "power: 200W}");
  } else if (lights.size() > limits::studio::kLights.max) {
    error(lights, fmt::format("{} lights; a studio here has at most {}", lights.size(),
                              limits::studio::kLights.max));
  } else {
    for (const auto& light : lights) read_light(light, scene);
  }
}

void Checker::read_light(const YAML::Node& node, spec::SceneSpec& scene) {
  spec::LightSpec light_spec;
  ir::Light& light = light_spec.light;
  light.loc = loc(node);
  if (!expect_map(node, "a light")) return;
  if (!node["type"]) {
    error(node, "a light needs a 'type': point, spot, directional or area");
    return;
  }
  const std::optional<ir::LightType> type = light_type(node["type"]);
  if (!type) return;
  light.type = *type;
  std::vector<std::string> allowed = {"type", "temperature"};
  switch (light.type) {
    case ir::LightType::kPoint:
      allowed.insert(allowed.end(), {"position", "power"});
      break;
    case ir::LightType::kSpot:
      allowed.insert(allowed.end(),
                     {"position", "power", "direction", "look_at", "angle", "blend"});
      break;
    case ir::LightType::kDirectional:
      allowed.insert(allowed.end(), {"direction", "illuminance"});
      break;
    case ir::LightType::kArea:
      allowed.insert(allowed.end(), {"position", "power", "direction", "look_at", "size"});
      break;
  }
  const std::string type_name = node["type"].Scalar();
  check_keys(node, allowed, fmt::format("a {} light", type_name));
  read_light_source(node, type_name, light);
  read_light_aim(node, light_spec);
  read(node, "temperature", "colour temperature", limits::studio::kLightTemperature,
       light.temperature_k);
  read_light_shape(node, light);
  scene.lights.push_back(light_spec);
}

std::optional<ir::LightType> Checker::light_type(const YAML::Node& node) {
  auto type = scalar(node, "light type");
  if (!type) return std::nullopt;
  if (*type == "point") return ir::LightType::kPoint;
  if (*type == "spot") return ir::LightType::kSpot;
  if (*type == "directional") return ir::LightType::kDirectional;
  if (*type == "area") return ir::LightType::kArea;
  error(node, fmt::format("unknown light type '{}'", *type) +
                  did_you_mean(*type, {"point", "spot", "directional", "area"},
                               " (expected point, spot, directional or area)"));
  return std::nullopt;
}

// Where the light is and how strong: a position and a power, or a directional light's
// illuminance.
void Checker::read_light_source(const YAML::Node& node, const std::string& type, ir::Light& light) {
  if (light.type != ir::LightType::kDirectional) {
    if (!node["position"]) {
      if (lacks(node, "position")) error(node, fmt::format("a {} light needs a 'position'", type));
    } else if (auto p = vec3(node["position"], "light position", limits::studio::kLightPosition)) {
      light.position = *p;
    }
    if (!node["power"]) {
      if (lacks(node, "power"))
        error(node, fmt::format("a {} light needs a 'power' (e.g. 200W)", type));
    } else if (auto w = quantity(node["power"], "light power", limits::studio::kLightPower)) {
      light.power_w = *w;
    }
  } else {
    if (!node["illuminance"]) {
      error(node, "a directional light needs an 'illuminance' (e.g. 2000lx)");
    } else if (auto e = quantity(node["illuminance"], "illuminance",
                                 limits::studio::kLightIlluminance)) {
      light.illuminance_lx = *e;
    }
    if (!node["direction"]) error(node, "a directional light needs a 'direction' [x, y, z]");
  }
}

// A direction, or a point to look at (spot and area lights look at the object by default).
void Checker::read_light_aim(const YAML::Node& node, spec::LightSpec& light_spec) {
  ir::Light& light = light_spec.light;
  if (node["direction"] && node["look_at"]) {
    error(node["look_at"], "give a light either 'direction' or 'look_at', not both");
  }
  if (node["direction"]) {
    if (auto d =
            direction(node["direction"], "light direction", "light direction must not be zero")) {
      light.direction = *d;
    }
  } else if (node["look_at"]) {
    light_spec.look_at = target(node["look_at"], "look_at", limits::studio::kLightLookAt);
  } else if (light.type == ir::LightType::kSpot || light.type == ir::LightType::kArea) {
    light_spec.look_at = Target{};
    light_spec.look_at->loc = light.loc;
  }
}

// An area light's size; a spot light's cone.
void Checker::read_light_shape(const YAML::Node& node, ir::Light& light) {
  namespace limit = limits::studio;
  if (node["size"]) {
    const YAML::Node size = node["size"];
    if (!size.IsSequence() || size.size() != 2) {
      error(size, "area light size must be [width, height]");
    } else {
      auto w = quantity(size[0], "area light width", limit::kAreaLightSize);
      auto h = quantity(size[1], "area light height", limit::kAreaLightSize);
      if (w && h) light.size_m = {*w, *h};
    }
  } else if (light.type == ir::LightType::kArea) {
    error(node, "an area light needs a 'size' [width, height]");
  }
  if (light.type == ir::LightType::kSpot) {
    light.spot_angle_rad = 45 * kDegree;
    read(node, "angle", "spot angle", limit::kSpotAngle, light.spot_angle_rad);
    read(node, "blend", "spot blend", limit::kSpotBlend, light.spot_blend);
  }
}

void Checker::read_camera(const YAML::Node& node, spec::SceneSpec& scene) {
  ir::Camera& camera = scene.camera;
  camera.loc = loc(node);
  if (!expect_map(node, "camera")) return;
  check_keys(node,
             {"body", "sensor", "intrinsics", "make", "model", "lens", "exposure", "focus",
              "white_balance", "effects", "output"},
             "camera");
  read_camera_kind(node, scene);
  read_exif_text(node, camera);
  // Intrinsics give the focal length in pixels: the lens may then leave out its focal length.
  const bool has_intrinsics = static_cast<bool>(node["intrinsics"]);
  if (const YAML::Node lens = node["lens"]) {
    read_lens(lens, camera, !has_intrinsics);
  } else if (!has_intrinsics) {
    error(node, "the camera needs a 'lens' with a focal_length");
  }
  if (scene.intrinsics) size_intrinsics_camera(node, scene);
  if (const YAML::Node exposure = node["exposure"]) {
    read_exposure(exposure, camera);
  } else {
    error(node, "the camera needs an 'exposure' {aperture, shutter, iso}");
  }
  if (const YAML::Node focus = node["focus"]) read_focus(focus, scene);
  check_lens_limits(node, scene);
  if (const YAML::Node wb = node["white_balance"]) read_white_balance(wb, camera);
  if (const YAML::Node effects = node["effects"]) read_effects(effects, camera);
  if (const YAML::Node output = node["output"]) read_output(output, camera);
  finish_camera(camera, has_intrinsics);
}

// What the camera is: a body preset, a sensor, or measured intrinsics (exactly one of them).
void Checker::read_camera_kind(const YAML::Node& node, spec::SceneSpec& scene) {
  const bool has_body = static_cast<bool>(node["body"]);
  const bool has_sensor = static_cast<bool>(node["sensor"]);
  const bool has_intrinsics = static_cast<bool>(node["intrinsics"]);
  if (has_intrinsics && (has_body || has_sensor)) {
    error(node["intrinsics"],
          fmt::format("give the camera either 'intrinsics' or a '{}', not both: the intrinsics "
                      "fix the image size and the focal length in pixels",
                      has_body ? "body" : "sensor"));
    return;
  }
  if (has_body && has_sensor) {
    error(node["sensor"], "give the camera either a 'body' preset or a 'sensor', not both");
  } else if (!has_body && !has_sensor && !has_intrinsics) {
    error(node,
          "the camera needs a 'body' preset (e.g. canon-6d) or a 'sensor' {width, height, "
          "pixels}");
  }
  if (has_body) read_body(node["body"], scene.camera);
  if (has_sensor) read_sensor(node["sensor"], scene.camera);
  if (has_intrinsics) read_intrinsics(node["intrinsics"], scene);
}

void Checker::read_body(const YAML::Node& body, ir::Camera& camera) {
  auto name = scalar(body, "body");
  if (!name) return;
  if (auto preset = find_body_preset(*name)) {
    camera.body = preset->name;
    camera.make = preset->make;
    camera.model = preset->model;
    camera.sensor_width_m = preset->sensor_width_m;
    camera.sensor_height_m = preset->sensor_height_m;
    camera.width_px = preset->width_px;
    camera.height_px = preset->height_px;
    camera.noise = preset->noise;
  } else {
    std::vector<std::string> names;
    for (const auto& p : body_presets()) names.push_back(p.name);
    error(body, fmt::format("unknown camera body '{}'", *name) +
                    did_you_mean(*name, names, fmt::format(" (known: {})", comma_list(names))));
  }
}

void Checker::read_sensor(const YAML::Node& sensor, ir::Camera& camera) {
  namespace limit = limits::camera;
  camera.body = "custom";
  camera.make = "RigC";
  camera.model = "custom sensor";
  if (!expect_map(sensor, "sensor")) return;
  check_keys(sensor, {"width", "height", "pixels"}, "sensor");
  for (const char* key : {"width", "height", "pixels"}) {
    if (lacks(sensor, key)) error(sensor, fmt::format("sensor needs '{}'", key));
  }
  read(sensor, "width", "sensor width", limit::kSensorWidth, camera.sensor_width_m);
  read(sensor, "height", "sensor height", limit::kSensorHeight, camera.sensor_height_m);
  if (const YAML::Node pixels = sensor["pixels"]) {
    if (!pixels.IsSequence() || pixels.size() != 2) {
      error(pixels, "sensor pixels must be [width, height]");
    } else {
      auto w = integer(pixels[0], "sensor pixel width", limit::kSensorPixels);
      auto h = integer(pixels[1], "sensor pixel height", limit::kSensorPixels);
      if (w && h) {
        camera.width_px = *w;
        camera.height_px = *h;
      }
    }
  }
}

// A camera known by its intrinsics (a calibration's, COLMAP's PINHOLE): the image size, fx, fy
// and the principal point in pixels (pixel centres at +0.5), kept as given.
void Checker::read_intrinsics(const YAML::Node& node, spec::SceneSpec& scene) {
  namespace limit = limits::camera;
  ir::Camera& camera = scene.camera;
  camera.body = "custom";
  camera.make = "RigC";
  camera.model = "custom intrinsics";
  if (!expect_map(node, "intrinsics")) return;
  check_keys(node, {"width", "height", "fx", "fy", "cx", "cy", "pixel_pitch"}, "intrinsics");
  bool complete = true;
  for (const char* key : {"width", "height", "fx", "fy", "cx", "cy"}) {
    if (node[key]) continue;
    complete = false;
    if (lacks(node, key)) error(node, fmt::format("intrinsics need '{}'", key));
  }
  const int errors_before = diag_.error_count();
  spec::IntrinsicsSpec k;
  k.loc = loc(node);
  const auto pixels = [&](const char* key, const limits::Integer& limit) {
    return node[key] ? integer(node[key], fmt::format("image {}", key), limit) : std::nullopt;
  };
  const std::optional<int> width = pixels("width", limit::kIntrinsicsWidth);
  const std::optional<int> height = pixels("height", limit::kIntrinsicsHeight);
  camera.width_px = width.value_or(camera.width_px);
  camera.height_px = height.value_or(camera.height_px);
  if (node["fx"]) k.fx = focal_length_px(node["fx"], "fx", limit::kIntrinsicsFx).value_or(0);
  if (node["fy"]) k.fy = focal_length_px(node["fy"], "fy", limit::kIntrinsicsFy).value_or(0);
  // The principal point is checked against a valid image size only.
  if (width) read_principal_point(node, "cx", *width, k.cx);
  if (height) read_principal_point(node, "cy", *height, k.cy);
  if (node["pixel_pitch"]) {
    k.pixel_pitch_m = quantity(node["pixel_pitch"], "pixel pitch", limit::kPixelPitch);
  }
  if (complete && diag_.error_count() == errors_before) scene.intrinsics = k;
}

// A focal length in pixels: positive and within `limit`.
std::optional<double> Checker::focal_length_px(const YAML::Node& node, const std::string& what,
                                               const limits::Quantity& limit) {
  const std::optional<double> value = quantity(node, limit.kind, what);
  if (!value) return std::nullopt;
  if (!(*value > 0)) {
    error(node, fmt::format("{} {:g} is not a positive focal length in pixels", what, *value));
    return std::nullopt;
  }
  return quantity(node, what, limit);
}

// cx or cy: inside the image of `size_px` pixels (its edges at 0 and size_px).
void Checker::read_principal_point(const YAML::Node& node, const char* key, int size_px,
                                   double& out) {
  if (!node[key]) return;
  const std::optional<double> value = quantity(node[key], QuantityKind::kNumber, key);
  if (!value) return;
  if (!(*value > 0 && *value < size_px)) {
    error(node[key], fmt::format("{} {:g} px is outside the image (0..{} px; pixel centres are "
                                 "at +0.5, the image centre at {:g})",
                                 key, *value, size_px, size_px / 2.0));
    return;
  }
  out = *value;
}

// The size in metres of an intrinsics camera, so that its focal length, depth of field and
// exposure mean something: a pixel pitch (given, else the lens's focal length / fx, else 5 um)
// makes the focal length fx·pitch and the sensor width·pitch by height·pitch·fx/fy.
void Checker::size_intrinsics_camera(const YAML::Node& node, spec::SceneSpec& scene) {
  constexpr double kDefaultPixelPitch_m = 5e-6;
  constexpr double kFocalTolerance = 0.01;  // of the focal length
  ir::Camera& camera = scene.camera;
  const spec::IntrinsicsSpec& k = *scene.intrinsics;
  // The lens's focal length, or its preset's (then at the preset's line).
  const YAML::Node lens = node["lens"];
  const bool focal = lens && lens.IsMap() && (lens["focal_length"] || lens["preset"]);
  const YAML::Node focal_node = !focal                 ? node
                                : lens["focal_length"] ? lens["focal_length"]
                                                       : lens["preset"];
  const auto mm = [](double m) { return fmt::format("{:g}mm", m * 1000); };
  const auto um = [](double m) { return fmt::format("{:g}um", m * 1e6); };
  double pitch = kDefaultPixelPitch_m;
  if (k.pixel_pitch_m) {
    pitch = *k.pixel_pitch_m;
    if (focal &&
        std::abs(camera.focal_length_m - k.fx * pitch) > kFocalTolerance * camera.focal_length_m) {
      error(focal_node, fmt::format("focal length {} disagrees with the intrinsics: fx {:g} px at "
                                    "pixel pitch {} is {}; give one of them",
                                    mm(camera.focal_length_m), k.fx, um(pitch), mm(k.fx * pitch)));
      return;
    }
  } else if (focal) {
    pitch = camera.focal_length_m / k.fx;
    const limits::Quantity& limit = limits::camera::kPixelPitch;
    if (pitch < limit.min || pitch > limit.max) {
      error(focal_node,
            fmt::format("focal length {} over fx {:g} px is a pixel pitch of {}, outside "
                        "{}..{}",
                        mm(camera.focal_length_m), k.fx, um(pitch), um(limit.min), um(limit.max)));
      return;
    }
  }
  if (!focal) camera.focal_length_m = k.fx * pitch;
  camera.sensor_width_m = camera.width_px * pitch;
  camera.sensor_height_m = camera.height_px * pitch * k.fx / k.fy;
}

// The EXIF make and model: one line of printable text that fits in a JPEG marker (libjpeg
// aborts, "Bogus marker length", on a longer one). EXIF text is NUL-terminated, so a "\0"
// would cut the tag short.
void Checker::read_exif_text(const YAML::Node& node, ir::Camera& camera) {
  const std::tuple<const char*, std::string*, limits::Count> fields[] = {
      {"make", &camera.make, limits::camera::kMake},
      {"model", &camera.model, limits::camera::kModel}};
  for (const auto& [key, field, limit] : fields) {
    if (!node[key]) continue;
    auto v = scalar(node[key], key);
    if (!v) continue;
    const bool control =
        std::any_of(v->begin(), v->end(), [](unsigned char c) { return c < 0x20 || c == 0x7F; });
    if (v->size() > limit.max) {
      error(node[key],
            fmt::format("camera {} is {} bytes long; at most {}", key, v->size(), limit.max));
    } else if (control) {
      error(node[key], fmt::format("camera {} holds a control character (EXIF text is one line "
                                   "of printable characters)",
                                   key));
    } else {
      *field = *v;
    }
  }
}

void Checker::read_lens(const YAML::Node& lens, ir::Camera& camera, bool needs_focal_length) {
  namespace limit = limits::camera;
  if (!expect_map(lens, "lens")) return;
  check_keys(lens, {"preset", "focal_length", "distortion", "vignetting"}, "lens");
  if (lens["focal_length"]) {
    read(lens, "focal_length", "focal length", limit::kFocalLength, camera.focal_length_m);
  } else if (needs_focal_length && !lens["preset"] && lacks(lens, "focal_length")) {
    error(lens, "lens needs a 'focal_length' (e.g. 50mm) or a 'preset'");
  }
  if (lens["preset"]) read_lens_preset(lens, camera);
  if (const YAML::Node distortion = lens["distortion"]) read_distortion(distortion, camera);
  read(lens, "vignetting", "vignetting", limit::kVignetting, camera.vignetting);
}

// A lens preset: a prime's focal length when none is given; a given one within its range.
void Checker::read_lens_preset(const YAML::Node& lens, ir::Camera& camera) {
  const YAML::Node node = lens["preset"];
  auto name = scalar(node, "lens preset");
  if (!name) return;
  lens_preset_ = find_lens_preset(*name);
  if (!lens_preset_) {
    std::vector<std::string> names;
    for (const auto& p : lens_presets()) names.push_back(p.name);
    error(node, fmt::format("unknown lens '{}'", *name) +
                    did_you_mean(*name, names, fmt::format(" (known: {})", comma_list(names))));
    return;
  }
  const LensPreset& preset = *lens_preset_;
  const auto mm = [](double m) { return fmt::format("{:g}mm", m * 1000); };
  const std::string range = preset.zoom()
                                ? mm(preset.shortest_focal_m) + "-" + mm(preset.longest_focal_m)
                                : mm(preset.shortest_focal_m);
  if (!lens["focal_length"]) {
    if (preset.zoom()) {
      error(lens, fmt::format("the zoom lens {} needs a 'focal_length' in {}", preset.name, range));
    }
    camera.focal_length_m = preset.shortest_focal_m;
    return;
  }
  constexpr double kTolerance_m = 0.05e-3;  // focal lengths are written to the millimetre
  if (camera.focal_length_m < preset.shortest_focal_m - kTolerance_m ||
      camera.focal_length_m > preset.longest_focal_m + kTolerance_m) {
    error(lens["focal_length"], fmt::format("focal length {} is outside the lens {}'s {}",
                                            mm(camera.focal_length_m), preset.name, range));
  }
}

// The aperture and a fixed focus distance within what the preset lens can do.
void Checker::check_lens_limits(const YAML::Node& node, spec::SceneSpec& scene) {
  if (!lens_preset_) return;
  const LensPreset& lens = *lens_preset_;
  scene.lens_preset = lens.name;
  scene.lens_min_focus_m = lens.min_focus_m;
  const ir::Camera& camera = scene.camera;
  const YAML::Node aperture = node["exposure"] ? node["exposure"]["aperture"] : YAML::Node();
  constexpr double kStopRounding = 0.02;  // f-numbers are written rounded (f/1.8 for f/1.78)
  if (aperture && camera.aperture_f_number < lens.widest_f_number * (1 - kStopRounding)) {
    error(aperture, fmt::format("f/{:g} is wider than the lens {} opens (f/{:g} at the widest)",
                                camera.aperture_f_number, lens.name, lens.widest_f_number));
  } else if (aperture && camera.aperture_f_number > lens.narrowest_f_number * (1 + kStopRounding)) {
    error(aperture, fmt::format("f/{:g} is narrower than the lens {} closes (f/{:g} at the "
                                "narrowest)",
                                camera.aperture_f_number, lens.name, lens.narrowest_f_number));
  }
  if (node["focus"] && !scene.focus_auto && scene.focus_distance_m < lens.min_focus_m) {
    error(node["focus"], fmt::format("focus at {:.3g}m is closer than the lens {} focuses "
                                     "({:g}m at the closest)",
                                     scene.focus_distance_m, lens.name, lens.min_focus_m));
  }
}

void Checker::read_distortion(const YAML::Node& distortion, ir::Camera& camera) {
  namespace limit = limits::camera;
  if (!expect_map(distortion, "distortion")) return;
  camera.distortion_loc = loc(distortion);
  check_keys(distortion, {"k1", "k2", "k3", "p1", "p2"}, "distortion");
  read(distortion, "k1", "k1", limit::kDistortionK1, camera.distortion.k1);
  read(distortion, "k2", "k2", limit::kDistortionK2, camera.distortion.k2);
  read(distortion, "k3", "k3", limit::kDistortionK3, camera.distortion.k3);
  read(distortion, "p1", "p1", limit::kDistortionP1, camera.distortion.p1);
  read(distortion, "p2", "p2", limit::kDistortionP2, camera.distortion.p2);
}

void Checker::read_exposure(const YAML::Node& exposure, ir::Camera& camera) {
  namespace limit = limits::camera;
  if (!expect_map(exposure, "exposure")) return;
  check_keys(exposure, {"aperture", "shutter", "iso"}, "exposure");
  for (const char* key : {"aperture", "shutter", "iso"}) {
    if (lacks(exposure, key)) error(exposure, fmt::format("exposure needs '{}'", key));
  }
  if (exposure["aperture"]) camera.aperture_loc = loc(exposure["aperture"]);
  if (exposure["shutter"]) camera.shutter_loc = loc(exposure["shutter"]);
  if (exposure["iso"]) camera.iso_loc = loc(exposure["iso"]);
  read(exposure, "aperture", "aperture", limit::kAperture, camera.aperture_f_number);
  read(exposure, "shutter", "shutter", limit::kShutter, camera.shutter_s);
  read(exposure, "iso", "ISO", limit::kIso, camera.iso);
}

void Checker::read_focus(const YAML::Node& focus, spec::SceneSpec& scene) {
  scene.camera.focus_loc = loc(focus);
  if (focus.IsScalar() && focus.Scalar() == "auto") {
    scene.focus_auto = true;
  } else if (auto d = quantity(focus, "focus distance", limits::camera::kFocusDistance)) {
    scene.focus_auto = false;
    scene.focus_distance_m = *d;
  }
}

void Checker::read_white_balance(const YAML::Node& wb, ir::Camera& camera) {
  if (wb.IsScalar() && wb.Scalar() == "auto") {
    camera.white_balance = ir::WhiteBalanceMode::kAuto;
  } else if (auto k = quantity(wb, "white balance", limits::camera::kWhiteBalance)) {
    camera.white_balance = ir::WhiteBalanceMode::kKelvin;
    camera.white_balance_k = *k;
  }
}

void Checker::read_effects(const YAML::Node& effects, ir::Camera& camera) {
  if (!expect_map(effects, "effects")) return;
  check_keys(effects,
             {"depth_of_field", "diffraction", "motion_blur", "distortion", "vignetting", "noise"},
             "effects");
  auto read_switch = [&](const char* key, bool& out) {
    if (!effects[key]) return;
    if (auto v = boolean(effects[key], key)) out = *v;
  };
  read_switch("depth_of_field", camera.effects.depth_of_field);
  read_switch("diffraction", camera.effects.diffraction);
  read_switch("motion_blur", camera.effects.motion_blur);
  read_switch("distortion", camera.effects.distortion);
  read_switch("vignetting", camera.effects.vignetting);
  read_switch("noise", camera.effects.noise);
}

void Checker::read_output(const YAML::Node& output, ir::Camera& camera) {
  if (!expect_map(output, "output")) return;
  check_keys(output, {"format", "quality"}, "output");
  if (output["format"]) {
    if (auto f = scalar(output["format"], "output format")) {
      if (*f == "jpeg" || *f == "jpg")
        camera.format = ir::ImageFormat::kJpeg;
      else if (*f == "png16")
        camera.format = ir::ImageFormat::kPng16;
      else if (*f == "tiff16")
        camera.format = ir::ImageFormat::kTiff16;
      else {
        error(output["format"],
              fmt::format("unknown output format '{}' (expected jpeg, png16 or tiff16)", *f));
      }
    }
  }
  read(output, "quality", "JPEG quality", limits::camera::kJpegQuality, camera.jpeg_quality);
}

// What follows from the sensor: the circle of confusion, and a warning on non-square pixels
// (unless they were measured: a calibration's fx and fy are what they are).
void Checker::finish_camera(ir::Camera& camera, bool pixels_measured) {
  // Acceptable circle of confusion: the sensor diagonal / 1500 (0.029 mm for full frame).
  camera.circle_of_confusion_m = std::hypot(camera.sensor_width_m, camera.sensor_height_m) / 1500.0;
  if (pixels_measured) return;
  const double pixel_aspect =
      (camera.sensor_width_m / camera.width_px) / (camera.sensor_height_m / camera.height_px);
  if (std::abs(pixel_aspect - 1) > 0.02) {
    diag_.warning(camera.loc, fmt::format("the sensor's pixels are not square (aspect {:.3f}); "
                                          "check the sensor size and pixel counts",
                                          pixel_aspect));
  }
}

void Checker::read_shots(const YAML::Node& node, spec::SceneSpec& scene) {
  if (!node.IsSequence() || node.size() == 0) {
    error(node, "shots must be a non-empty list of turntable, orbit or pose entries");
    return;
  }
  for (const auto& entry : node) {
    spec::ShotGroupSpec group;
    group.loc = loc(entry);
    if (!entry.IsMap() || entry.size() != 1) {
      error(entry, "each shot entry has exactly one key: turntable, orbit or pose");
      continue;
    }
    const YAML::Node key = entry.begin()->first;
    const YAML::Node body = entry.begin()->second;
    if (!check_keys(entry, {"turntable", "orbit", "pose"}, "shots")) continue;
    const std::string kind = key.Scalar();
    if (kind == "turntable")
      read_turntable_shots(body, group);
    else if (kind == "orbit")
      read_orbit_shots(body, group);
    else
      read_pose_shot(body, group);
    scene.shots.push_back(group);
  }
}

void Checker::read_turntable_shots(const YAML::Node& node, spec::ShotGroupSpec& group) {
  namespace limit = limits::shots;
  group.kind = ir::ShotKind::kTurntable;
  spec::TurntableShotsSpec& shots = group.turntable;
  if (!expect_map(node, "turntable shots")) return;
  check_keys(node, {"steps", "step", "start", "speed", "camera"}, "turntable shots");
  read(node, "steps", "turntable steps", limit::kTurntableSteps, shots.steps);
  if (node["step"]) {
    read(node, "step", "turntable step", limit::kTurntableStep, shots.step_rad);
  } else {
    shots.step_rad = 2 * std::numbers::pi / shots.steps;
  }
  read(node, "start", "turntable start", limit::kTurntableStart, shots.start_rad);
  read(node, "speed", "turntable speed", limit::kTurntableSpeed, shots.speed_rad_s);
  if (const YAML::Node camera = node["camera"]) {
    read_turntable_camera(camera, shots.camera);
  } else {
    error(node, "turntable shots need a 'camera' {distance, height}");
  }
}

void Checker::read_turntable_camera(const YAML::Node& camera, spec::TurntableCameraSpec& out) {
  namespace limit = limits::shots;
  if (!expect_map(camera, "turntable camera")) return;
  check_keys(camera, {"distance", "height", "azimuth", "aim"}, "turntable camera");
  read(camera, "distance", "camera distance", limit::kTurntableCameraDistance, out.distance_m);
  read(camera, "height", "camera height", limit::kTurntableCameraHeight, out.height_m);
  read(camera, "azimuth", "camera azimuth", limit::kTurntableCameraAzimuth, out.azimuth_rad);
  if (camera["aim"]) {
    if (auto t = target(camera["aim"], "aim", limit::kTurntableCameraAim)) out.aim = *t;
  }
}

void Checker::read_orbit_shots(const YAML::Node& node, spec::ShotGroupSpec& group) {
  group.kind = ir::ShotKind::kOrbit;
  spec::OrbitShotsSpec& orbit = group.orbit;
  if (!expect_map(node, "orbit shots")) return;
  check_keys(node, {"rings", "distance", "aim"}, "orbit shots");
  if (node["distance"]) {
    read(node, "distance", "orbit distance", limits::shots::kOrbitDistance, orbit.distance_m);
  } else {
    error(node, "orbit shots need a 'distance' from the object");
  }
  if (node["aim"]) {
    if (auto t = target(node["aim"], "aim", limits::shots::kOrbitAim)) orbit.aim = *t;
  }
  const YAML::Node rings = node["rings"];
  if (!rings || !rings.IsSequence() || rings.size() == 0) {
    error(rings ? rings : node, "orbit shots need 'rings': a list of {elevation, count}");
    return;
  }
  for (const auto& ring : rings) read_ring(ring, orbit);
}

void Checker::read_ring(const YAML::Node& node, spec::OrbitShotsSpec& orbit) {
  namespace limit = limits::shots;
  spec::RingSpec ring;
  ring.loc = loc(node);
  if (!expect_map(node, "a ring")) return;
  check_keys(node, {"elevation", "count", "start"}, "a ring");
  read(node, "elevation", "ring elevation", limit::kRingElevation, ring.elevation_rad);
  if (node["count"]) {
    read(node, "count", "ring count", limit::kRingCount, ring.count);
  } else {
    error(node, "a ring needs a 'count' of shots");
  }
  read(node, "start", "ring start", limit::kRingStart, ring.start_rad);
  orbit.rings.push_back(ring);
}

void Checker::read_pose_shot(const YAML::Node& node, spec::ShotGroupSpec& group) {
  group.kind = ir::ShotKind::kPose;
  spec::PoseShotSpec& pose = group.pose;
  if (!expect_map(node, "a pose shot")) return;
  check_keys(node, {"position", "look_at", "rotation", "up", "turntable"}, "a pose shot");
  if (node["position"]) {
    if (auto p = vec3(node["position"], "camera position", limits::shots::kPosePosition)) {
      pose.position = *p;
    }
  } else {
    error(node, "a pose shot needs a 'position'");
  }
  read_pose_aim(node, pose);
  read(node, "turntable", "turntable angle", limits::shots::kPoseTurntable, pose.turntable_rad);
}

// Where the camera looks: at a target (with an up direction), or along a rotation.
void Checker::read_pose_aim(const YAML::Node& node, spec::PoseShotSpec& pose) {
  pose.look_at.loc = loc(node);
  if (const YAML::Node rotation_node = node["rotation"]) {
    if (node["look_at"]) {
      error(rotation_node, "give a pose either 'look_at' or 'rotation', not both");
    } else if (node["up"]) {
      error(node["up"], "'up' goes with 'look_at': a 'rotation' fixes the camera's roll itself");
    } else {
      pose.camera_from_world = rotation(rotation_node);
    }
    return;
  }
  if (node["look_at"]) {
    if (auto t = target(node["look_at"], "look_at", limits::shots::kPoseLookAt)) {
      pose.look_at = *t;
    }
  }
  if (node["up"]) {
    if (auto u = direction(node["up"], "up", "up must not be zero")) pose.up = *u;
  }
}

// How far a given rotation may be from one (R^T R from the identity, entry by entry).
constexpr double kRotationTolerance = 1e-4;

// COLMAP's camera_from_world rotation, a 3x3 matrix or {quaternion: [qw, qx, qy, qz]}: a proper
// rotation within kRotationTolerance, re-orthonormalised (the nearest rotation, by SVD) so that
// values written to a few digits give an exact one.
std::optional<Eigen::Matrix3d> Checker::rotation(const YAML::Node& node) {
  std::optional<Eigen::Matrix3d> r =
      node.IsMap() ? rotation_quaternion(node) : rotation_matrix(node);
  if (!r) return std::nullopt;
  const double deviation =
      (r->transpose() * *r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(deviation <= kRotationTolerance)) {
    error(node, fmt::format("the rotation is not orthonormal (R^T R is {:.2g} off the identity; "
                            "at most {:g}): give COLMAP's camera_from_world rotation",
                            deviation, kRotationTolerance));
    return std::nullopt;
  }
  if (r->determinant() < 0) {
    error(node,
          "the rotation is a reflection (determinant -1), not a rotation: a camera_from_world "
          "rotation has determinant +1");
    return std::nullopt;
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(*r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return Eigen::Matrix3d(svd.matrixU() * svd.matrixV().transpose());
}

// [[r11, r12, r13], [r21, r22, r23], [r31, r32, r33]], rows first.
std::optional<Eigen::Matrix3d> Checker::rotation_matrix(const YAML::Node& node) {
  if (!node.IsSequence() || node.size() != 3) {
    error(node,
          "rotation must be a 3x3 matrix [[r11, r12, r13], [r21, r22, r23], [r31, r32, "
          "r33]] or {quaternion: [qw, qx, qy, qz]}");
    return std::nullopt;
  }
  Eigen::Matrix3d r;
  bool ok = true;
  for (int row = 0; row < 3; ++row) {
    const auto values = vec3(node[row], QuantityKind::kNumber, "a rotation's row");
    if (values) r.row(row) = values->transpose();
    ok = ok && values;
  }
  if (!ok) return std::nullopt;
  return r;
}

// {quaternion: [qw, qx, qy, qz]} (COLMAP's images.txt order), of unit norm.
std::optional<Eigen::Matrix3d> Checker::rotation_quaternion(const YAML::Node& node) {
  check_keys(node, {"quaternion"}, "rotation");
  const YAML::Node q = node["quaternion"];
  if (!q) {
    if (lacks(node, "quaternion")) error(node, "rotation needs a 'quaternion' [qw, qx, qy, qz]");
    return std::nullopt;
  }
  if (!q.IsSequence() || q.size() != 4) {
    error(q, "quaternion must be a list of four values [qw, qx, qy, qz] (COLMAP's order)");
    return std::nullopt;
  }
  Eigen::Vector4d wxyz;
  for (int i = 0; i < 4; ++i) {
    const auto value = quantity(q[i], QuantityKind::kNumber, "quaternion");
    if (!value) return std::nullopt;
    wxyz[i] = *value;
  }
  // Off unit norm by no more than a matrix may be off orthonormal.
  const double norm2 = wxyz.squaredNorm();
  if (!(std::abs(norm2 - 1) <= kRotationTolerance)) {
    error(q, fmt::format("quaternion of norm {:.6g} is not a unit quaternion (COLMAP writes unit "
                         "quaternions)",
                         std::sqrt(norm2)));
    return std::nullopt;
  }
  return Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]).normalized().toRotationMatrix();
}

// The mark of the first key or scalar value under `root` that is not UTF-8. yaml-cpp passes a
// Latin-1 byte through, and writing the IR or the manifest as JSON would then fail after the
// images are written.
std::optional<YAML::Mark> first_invalid_utf8_scalar(const YAML::Node& root) {
  std::vector<YAML::Node> pending = {root};
  // Aliases share nodes, so nested ones (a "billion laughs" file) repeat them exponentially: the
  // walk stops after a bound far beyond any scene's node count.
  constexpr int kMostNodes = 1 << 20;
  for (int visited = 0; !pending.empty() && visited < kMostNodes; ++visited) {
    const YAML::Node node = pending.back();
    pending.pop_back();
    if (node.IsScalar()) {
      if (!valid_utf8(node.Scalar())) return node.Mark();
    } else if (node.IsSequence()) {
      for (const auto& item : node) pending.push_back(item);
    } else if (node.IsMap()) {
      for (auto it = node.begin(); it != node.end(); ++it) {
        pending.push_back(it->first);
        pending.push_back(it->second);
      }
    }
  }
  return std::nullopt;
}

// Where each document of a YAML text starts and where its first node is, for at most two
// documents: enough to refuse a second one. (yaml-cpp 0.7's LoadAll never ends on some malformed
// texts, e.g. a lone ",": each "document" then starts where the last one did.)
struct DocumentStart {
  YAML::Mark start;
  std::optional<YAML::Mark> first_node;
};
class DocumentStarts : public YAML::EventHandler {
 public:
  std::vector<DocumentStart> documents;
  void OnDocumentStart(const YAML::Mark& mark) override { documents.push_back({mark, {}}); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { node(mark); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { node(mark); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string&) override {
    node(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    node(mark);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    node(mark);
  }
  void OnMapEnd() override {}

 private:
  void node(const YAML::Mark& mark) {
    if (!documents.empty() && !documents.back().first_node) documents.back().first_node = mark;
  }
};

std::vector<DocumentStart> first_two_documents(const std::string& text) {
  std::istringstream in(text);
  YAML::Parser parser(in);
  DocumentStarts starts;
  while (starts.documents.size() < 2 && parser.HandleNextDocument(starts)) {
  }
  return starts.documents;
}

}  // namespace

std::optional<YAML::Node> parse_yaml(const std::string& text, const std::string& file,
                                     DiagnosticEngine& diag) {
  try {
    // yaml-cpp reads a NUL byte as "unknown escape character" or cuts the text there.
    if (const std::size_t nul = text.find('\0'); nul != std::string::npos) {
      const std::size_t line_start = text.rfind('\n', nul) + 1;  // npos + 1 == 0
      const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + nul, '\n'));
      diag.error({file, line, static_cast<int>(nul - line_start) + 1},
                 "a NUL byte: a scene file is text (a NUL inside quotes is written \\0)");
      return std::nullopt;
    }
    // Before building the tree: an alias bomb or deep nesting would exhaust memory or the stack.
    if (const auto problem = yaml_shape_problem(text)) {
      diag.error({file, problem->line + 1, problem->column + 1}, problem->message);
      return std::nullopt;
    }
    // Two documents at most, so that a second one is an error rather than silently left unread.
    const std::vector<DocumentStart> documents = first_two_documents(text);
    if (documents.size() > 1) {
      const bool stuck = documents[1].start.pos == documents[0].start.pos;
      const YAML::Mark mark =
          stuck ? documents[0].start : documents[1].first_node.value_or(documents[1].start);
      diag.error({file, std::max(mark.line, 0) + 1, std::max(mark.column, 0) + 1},
                 stuck ? "YAML syntax error: unexpected character"
                       : "a scene file holds one YAML document; a second one starts here");
      return std::nullopt;
    }
    const YAML::Node root = documents.empty() ? YAML::Node() : YAML::Load(text);
    if (const auto bad = first_invalid_utf8_scalar(root)) {
      diag.error({file, bad->line + 1, bad->column + 1},
                 "this text is not valid UTF-8 (save the scene file as UTF-8)");
      return std::nullopt;
    }
    return root;
  } catch (const YAML::ParserException& e) {
    diag.error({file, e.mark.line + 1, e.mark.column + 1},
               fmt::format("YAML syntax error: {}", e.msg));
  } catch (const YAML::Exception& e) {
    diag.error({file, e.mark.line + 1, e.mark.column + 1}, fmt::format("YAML error: {}", e.msg));
  }
  return std::nullopt;
}

std::optional<spec::SceneSpec> check_scene(const YAML::Node& root, const std::string& file,
                                           const std::string& base_dir, DiagnosticEngine& diag) {
  Checker checker(file, base_dir, diag);
  try {
    return checker.run(root);
  } catch (const YAML::Exception& e) {
    // yaml-cpp throws on some malformed trees (e.g. aliases to odd nodes); never crash.
    diag.error({file, e.mark.line + 1, e.mark.column + 1}, fmt::format("YAML error: {}", e.msg));
    return std::nullopt;
  }
}

}  // namespace rigc
