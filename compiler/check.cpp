#include "compiler/check.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <set>

#include "assets/primitives.h"
#include "compiler/presets.h"
#include "compiler/units.h"

namespace rigc {
namespace {

namespace fs = std::filesystem;
using spec::Target;
constexpr double kDeg = std::numbers::pi / 180.0;

constexpr std::size_t kMostLights = 32;

// Real cameras' EXIF Make and Model are a few dozen characters.
constexpr std::size_t kMaxExifText = 255;

// Why `name` cannot be one folder of a path, or empty when it can: the scene's name is the
// default run folder's parent (out/<name>/<backend>), and "/tmp/x" or "../../x" took runs there.
std::string folder_name_problem(const std::string& name) {
  if (name.empty()) return "it is empty";
  if (name.size() > 100) return "it is longer than 100 bytes";
  if (name == "." || name == "..") return "'.' and '..' are not folder names";
  for (const unsigned char c : name) {
    if (c == '/' || c == '\\') return "it holds a slash";
    if (c < 0x20 || c == 0x7F) return "it holds a control character";
  }
  return {};
}

struct Range {
  double min;
  double max;
  bool min_exclusive = false;
};

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
    // yaml-cpp keeps a repeated key's first value and drops the rest without a word: `iso: 200,
    // iso: 400` gave ISO 200.
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
      std::string suggestion = closest_match(key, allowed);
      std::string message = fmt::format("unknown key '{}' in {}", key, context);
      if (!suggestion.empty()) {
        message += fmt::format("; did you mean '{}'?", suggestion);
      } else {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        message += fmt::format(" (expected one of: {})", list);
      }
      error(it->first, message);
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

  std::optional<double> quantity(const YAML::Node& node, QuantityKind kind, const std::string& what,
                                 std::optional<Range> range = std::nullopt) {
    auto text = scalar(node, what);
    if (!text) return std::nullopt;
    QuantityParse parsed = parse_quantity(*text, kind);
    if (!parsed.value) {
      error(node, fmt::format("{}: {}", what, parsed.error));
      return std::nullopt;
    }
    double value = *parsed.value;
    if (range) {
      bool below = range->min_exclusive ? value <= range->min : value < range->min;
      if (below || value > range->max) {
        error(node,
              fmt::format("{} {} is outside {}..{}", what, format_quantity(value, kind),
                          format_quantity(range->min, kind), format_quantity(range->max, kind)));
        return std::nullopt;
      }
    }
    return value;
  }

  std::optional<int> integer(const YAML::Node& node, const std::string& what, int min, int max) {
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
    if (value < min || value > max) {
      error(node, fmt::format("{} {} is outside {}..{}", what, value, min, max));
      return std::nullopt;
    }
    return static_cast<int>(value);
  }

  std::optional<bool> boolean(const YAML::Node& node, const std::string& what) {
    auto text = scalar(node, what);
    if (!text) return std::nullopt;
    if (*text == "true" || *text == "on" || *text == "yes") return true;
    if (*text == "false" || *text == "off" || *text == "no") return false;
    error(node, fmt::format("{} must be true or false, got '{}'", what, *text));
    return std::nullopt;
  }

  std::optional<ir::Vec3> vec3(const YAML::Node& node, QuantityKind kind, const std::string& what,
                               std::optional<Range> range = std::nullopt) {
    if (!node.IsSequence() || node.size() != 3) {
      error(node, fmt::format("{} must be a list of three values [x, y, z]", what));
      return std::nullopt;
    }
    ir::Vec3 result;
    bool ok = true;
    for (int i = 0; i < 3; ++i) {
      auto v = quantity(node[i], kind, what, range);
      if (v)
        result[i] = *v;
      else
        ok = false;
    }
    if (!ok) return std::nullopt;
    return result;
  }

  std::optional<ir::Vec3> color(const YAML::Node& node, const std::string& what) {
    if (!node.IsSequence() || node.size() != 3) {
      error(node, fmt::format("{} must be a list of three linear RGB values in 0..1", what));
      return std::nullopt;
    }
    return vec3(node, QuantityKind::kNumber, what, Range{0, 1});
  }

  std::optional<Target> target(const YAML::Node& node, const std::string& what) {
    Target result;
    result.loc = loc(node);
    if (node.IsScalar()) {
      if (node.Scalar() == "object") return result;
      error(node, fmt::format("{} must be 'object' or a position [x, y, z], got '{}'", what,
                              node.Scalar()));
      return std::nullopt;
    }
    auto point = vec3(node, QuantityKind::kLength, what);
    if (!point) return std::nullopt;
    result.object = false;
    result.point = *point;
    return result;
  }

  void read_object(const YAML::Node& node, spec::SceneSpec& scene);
  void read_surface(const YAML::Node& node, spec::ObjectSpec& object);
  void read_studio(const YAML::Node& node, spec::SceneSpec& scene);
  void read_light(const YAML::Node& node, spec::SceneSpec& scene);
  void read_camera(const YAML::Node& node, spec::SceneSpec& scene);
  void read_shots(const YAML::Node& node, spec::SceneSpec& scene);
  void read_coverage(const YAML::Node& node, spec::SceneSpec& scene);
  void read_turntable_shots(const YAML::Node& node, spec::ShotGroupSpec& group);
  void read_orbit_shots(const YAML::Node& node, spec::ShotGroupSpec& group);
  void read_pose_shot(const YAML::Node& node, spec::ShotGroupSpec& group);

  std::string file_;
  std::string base_dir_;
  DiagnosticEngine& diag_;
};

const Range kPositiveLength{0, 1000, true};

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
    if (auto version = integer(root["rigc"], "language version 'rigc'", 1, 1)) {
      scene.version = *version;
    }
  } else {
    diag_.error({file_, 1, 1}, "missing 'rigc: 1' (the language version) at the top of the scene");
  }
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

void Checker::read_coverage(const YAML::Node& node, spec::SceneSpec& scene) {
  ir::CoverageSettings& coverage = scene.coverage;
  coverage.loc = loc(node);
  if (!expect_map(node, "coverage")) return;
  check_keys(node,
             {"min_pixels_per_mm2", "max_view_angle", "max_blur", "min_triangulation_angle",
              "min_signal", "max_signal", "min_overlap", "min_frame_fill"},
             "coverage");
  auto read = [&](const char* key, QuantityKind kind, Range range, double& out) {
    if (!node[key]) return;
    if (auto v = quantity(node[key], kind, key, range)) out = *v;
  };
  read("min_pixels_per_mm2", QuantityKind::kNumber, {0, 1e6}, coverage.min_pixels_per_mm2);
  read("max_view_angle", QuantityKind::kAngle, {1 * kDeg, 90 * kDeg}, coverage.max_view_angle_rad);
  read("max_blur", QuantityKind::kNumber, {0.1, 1000}, coverage.max_blur_px);
  read("min_triangulation_angle", QuantityKind::kAngle, {0, 90 * kDeg},
       coverage.min_triangulation_angle_rad);
  read("min_signal", QuantityKind::kNumber, {0, 1}, coverage.min_signal);
  read("max_signal", QuantityKind::kNumber, {0, 1}, coverage.max_signal);
  read("min_overlap", QuantityKind::kNumber, {0, 1}, coverage.min_overlap);
  read("min_frame_fill", QuantityKind::kNumber, {0, 1}, coverage.min_frame_fill);
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
  if (has_mesh) {
    if (auto path = scalar(node["mesh"], "mesh")) {
      object.mesh_path = spec::Located<std::string>{*path, loc(node["mesh"])};
      fs::path resolved = fs::path(*path);
      if (resolved.is_relative()) resolved = fs::path(base_dir_) / resolved;
      object.mesh_path_resolved = resolved.lexically_normal().string();
      std::error_code ec;
      if (!fs::exists(resolved, ec)) {
        error(node["mesh"], fmt::format("mesh file '{}' does not exist", resolved.string()));
      } else if (fs::is_directory(resolved, ec)) {
        error(node["mesh"], fmt::format("mesh '{}' is a folder, not a file", resolved.string()));
      } else {
        std::string ext = resolved.extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
        const std::set<std::string> formats = {".gltf", ".glb", ".obj", ".ply", ".stl"};
        if (!formats.count(ext)) {
          error(node["mesh"], fmt::format("mesh '{}' has an unsupported format '{}' (use glTF/GLB, "
                                          "OBJ, PLY or STL)",
                                          *path, ext));
        }
      }
    }
  }
  if (has_primitive) {
    const YAML::Node primitive = node["primitive"];
    // (yaml-cpp's Node::operator= writes through to the node, so pick the shape node once.)
    const YAML::Node shape = primitive.IsMap() ? primitive["shape"] : primitive;
    if (primitive.IsMap()) {
      check_keys(primitive, {"shape", "detail", "seed"}, "primitive");
      if (!shape) error(primitive, "primitive needs a 'shape' (sphere, box, cylinder, statue)");
      if (primitive["detail"]) {
        if (auto d = integer(primitive["detail"], "primitive detail", 1, 9)) {
          object.primitive_detail = *d;
        }
      }
      if (primitive["seed"]) {
        if (auto s = integer(primitive["seed"], "primitive seed", 0, 1 << 30)) {
          object.primitive_seed = static_cast<std::uint32_t>(*s);
        }
      }
    }
    if (shape) {
      if (auto name = scalar(shape, "primitive shape")) {
        if (!primitive_from_name(*name)) {
          std::string suggestion = closest_match(*name, primitive_names());
          error(shape,
                fmt::format("unknown primitive '{}'{}", *name,
                            suggestion.empty() ? " (expected sphere, box, cylinder or statue)"
                                               : fmt::format("; did you mean '{}'?", suggestion)));
        } else {
          object.primitive = spec::Located<std::string>{*name, loc(shape)};
        }
      }
    }
  }
  if (node["up"]) {
    if (auto up = scalar(node["up"], "up")) {
      if (*up == "y" || *up == "+y" || *up == "z" || *up == "+z" || *up == "-y" || *up == "-z") {
        object.up_axis = up->back();
        object.up_negative = (*up)[0] == '-';
      } else {
        error(node["up"], fmt::format("up must be y, z, -y or -z (the model file's up axis), got "
                                      "'{}'",
                                      *up));
      }
    }
  }
  if (node["fit"]) {
    const YAML::Node fit = node["fit"];
    if (expect_map(fit, "fit")) {
      check_keys(fit, {"height", "width", "size"}, "fit");
      if (fit.size() != 1) error(fit, "fit takes one of height, width or size");
      auto read = [&](const char* key, std::optional<spec::Located<double>>& out) {
        if (!fit[key]) return;
        if (auto v = quantity(fit[key], QuantityKind::kLength, fmt::format("fit {}", key),
                              Range{0.001, 100})) {
          out = spec::Located<double>{*v, loc(fit[key])};
        }
      };
      read("height", object.fit_height);
      read("width", object.fit_width);
      read("size", object.fit_size);
    }
  }
  if (node["scale"]) {
    if (node["scale"].IsSequence()) {
      if (auto s = vec3(node["scale"], QuantityKind::kNumber, "scale", Range{0, 1e6, true})) {
        object.scale = *s;
      }
    } else if (auto s =
                   quantity(node["scale"], QuantityKind::kNumber, "scale", Range{0, 1e6, true})) {
      object.scale = ir::Vec3::Constant(*s);
    }
  }
  if (node["rotate"]) {
    if (auto r = vec3(node["rotate"], QuantityKind::kAngle, "rotate")) object.rotate_rad = *r;
  }
  if (node["translate"]) {
    if (auto t = vec3(node["translate"], QuantityKind::kLength, "translate")) object.translate = *t;
  }
  if (node["surface"]) read_surface(node["surface"], object);
}

void Checker::read_surface(const YAML::Node& node, spec::ObjectSpec& object) {
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
        std::string suggestion = closest_match(*name, names);
        error(node["pattern"],
              fmt::format("unknown pattern '{}'{}", *name,
                          suggestion.empty() ? " (expected none, speckle, noise or checker)"
                                             : fmt::format("; did you mean '{}'?", suggestion)));
      }
    }
  }
  if (node["scale"]) {
    if (auto v =
            quantity(node["scale"], QuantityKind::kLength, "pattern scale", Range{0.0001, 1})) {
      object.pattern.scale_m = *v;
    }
  }
  if (node["contrast"]) {
    if (auto v = quantity(node["contrast"], QuantityKind::kNumber, "contrast", Range{0, 1})) {
      object.pattern.contrast = *v;
    }
  }
  if (node["seed"]) {
    if (auto v = integer(node["seed"], "pattern seed", 0, 1 << 30)) {
      object.pattern.seed = static_cast<std::uint32_t>(*v);
    }
  }
  if (node["color"]) object.surface_color = color(node["color"], "surface color");
  if (node["roughness"]) {
    object.roughness = quantity(node["roughness"], QuantityKind::kNumber, "roughness", Range{0, 1});
  }
  if (node["metallic"]) {
    object.metallic = quantity(node["metallic"], QuantityKind::kNumber, "metallic", Range{0, 1});
  }
}

void Checker::read_studio(const YAML::Node& node, spec::SceneSpec& scene) {
  if (!expect_map(node, "studio")) return;
  check_keys(node, {"turntable", "backdrop", "lights", "ambient", "floor"}, "studio");
  ir::Studio& studio = scene.studio;
  if (const YAML::Node table = node["turntable"]) {
    studio.turntable.loc = loc(table);
    if (expect_map(table, "turntable")) {
      check_keys(table, {"diameter", "height", "thickness", "color"}, "turntable");
      if (table["diameter"]) {
        if (auto v = quantity(table["diameter"], QuantityKind::kLength, "turntable diameter",
                              Range{0.01, 10})) {
          studio.turntable.diameter_m = *v;
        }
      }
      if (table["height"]) {
        if (auto v =
                quantity(table["height"], QuantityKind::kLength, "turntable height", Range{0, 5})) {
          studio.turntable.height_m = *v;
        }
      }
      if (table["thickness"]) {
        if (auto v = quantity(table["thickness"], QuantityKind::kLength, "turntable thickness",
                              Range{0.001, 1})) {
          studio.turntable.thickness_m = *v;
        }
      }
      if (table["color"]) {
        if (auto c = color(table["color"], "turntable color")) studio.turntable.color = *c;
      }
    }
  }
  if (const YAML::Node backdrop = node["backdrop"]) {
    studio.backdrop.loc = loc(backdrop);
    if (expect_map(backdrop, "backdrop")) {
      check_keys(backdrop, {"green_screen", "color", "distance", "width", "height"}, "backdrop");
      if (const YAML::Node green = backdrop["green_screen"]) {
        if (green.IsMap()) {
          check_keys(green, {"color"}, "green_screen");
          studio.backdrop.green_screen = true;
          if (green["color"]) {
            if (auto c = color(green["color"], "green screen color")) studio.backdrop.color = *c;
          }
        } else if (auto on = boolean(green, "green_screen")) {
          studio.backdrop.green_screen = *on;
        }
      }
      if (backdrop["color"]) {
        if (auto c = color(backdrop["color"], "backdrop color")) studio.backdrop.color = *c;
      }
      if (backdrop["distance"]) {
        if (auto v = quantity(backdrop["distance"], QuantityKind::kLength, "backdrop distance",
                              Range{0.05, 100})) {
          studio.backdrop.distance_m = *v;
          scene.backdrop_distance_set = true;
        }
      }
      if (backdrop["width"]) {
        if (auto v = quantity(backdrop["width"], QuantityKind::kLength, "backdrop width",
                              Range{0.1, 100})) {
          studio.backdrop.width_m = *v;
        }
      }
      if (backdrop["height"]) {
        if (auto v = quantity(backdrop["height"], QuantityKind::kLength, "backdrop height",
                              Range{0.1, 100})) {
          studio.backdrop.height_m = *v;
        }
      }
    }
  }
  if (const YAML::Node lights = node["lights"]) {
    if (!lights.IsSequence()) {
      error(lights,
            "lights must be a list, e.g. - {type: point, position: [1m, -1m, 1.5m], "
            "power: 200W}");
    } else if (lights.size() > kMostLights) {
      // Each light has a shadow map (tens of MB at full size): 2000 took 3.6 GB for one shot.
      error(lights,
            fmt::format("{} lights; a studio here has at most {}", lights.size(), kMostLights));
    } else {
      for (const auto& light : lights) read_light(light, scene);
    }
  }
  if (node["ambient"]) {
    if (auto v =
            quantity(node["ambient"], QuantityKind::kIlluminance, "ambient", Range{0, 200000})) {
      studio.ambient_lx = *v;
    }
  }
  if (const YAML::Node floor = node["floor"]) {
    if (expect_map(floor, "floor")) {
      check_keys(floor, {"color"}, "floor");
      if (floor["color"]) {
        if (auto c = color(floor["color"], "floor color")) studio.floor_color = *c;
      }
    }
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
  auto type = scalar(node["type"], "light type");
  if (!type) return;
  const std::vector<std::string> types = {"point", "spot", "directional", "area"};
  if (*type == "point")
    light.type = ir::LightType::kPoint;
  else if (*type == "spot")
    light.type = ir::LightType::kSpot;
  else if (*type == "directional")
    light.type = ir::LightType::kDirectional;
  else if (*type == "area")
    light.type = ir::LightType::kArea;
  else {
    std::string suggestion = closest_match(*type, types);
    error(node["type"],
          fmt::format("unknown light type '{}'{}", *type,
                      suggestion.empty() ? " (expected point, spot, directional or area)"
                                         : fmt::format("; did you mean '{}'?", suggestion)));
    return;
  }
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
  check_keys(node, allowed, fmt::format("a {} light", *type));
  if (light.type != ir::LightType::kDirectional) {
    if (!node["position"]) {
      if (lacks(node, "position")) error(node, fmt::format("a {} light needs a 'position'", *type));
    } else if (auto p = vec3(node["position"], QuantityKind::kLength, "light position")) {
      light.position = *p;
    }
    if (!node["power"]) {
      if (lacks(node, "power"))
        error(node, fmt::format("a {} light needs a 'power' (e.g. 200W)", *type));
    } else if (auto w = quantity(node["power"], QuantityKind::kPower, "light power",
                                 Range{0, 1e6, true})) {
      light.power_w = *w;
    }
  } else {
    if (!node["illuminance"]) {
      error(node, "a directional light needs an 'illuminance' (e.g. 2000lx)");
    } else if (auto e = quantity(node["illuminance"], QuantityKind::kIlluminance, "illuminance",
                                 Range{0, 200000, true})) {
      light.illuminance_lx = *e;
    }
    if (!node["direction"]) error(node, "a directional light needs a 'direction' [x, y, z]");
  }
  if (node["direction"] && node["look_at"]) {
    error(node["look_at"], "give a light either 'direction' or 'look_at', not both");
  }
  if (node["direction"]) {
    if (auto d = vec3(node["direction"], QuantityKind::kNumber, "light direction")) {
      // stableNorm: [1e200, 0, 0] overflowed norm() to inf and normalized() to a zero vector.
      if (d->stableNorm() < 1e-9) {
        error(node["direction"], "light direction must not be zero");
      } else {
        light.direction = d->stableNormalized();
      }
    }
  } else if (node["look_at"]) {
    light_spec.look_at = target(node["look_at"], "look_at");
  } else if (light.type == ir::LightType::kSpot || light.type == ir::LightType::kArea) {
    light_spec.look_at = Target{};  // aim at the object by default
    light_spec.look_at->loc = light.loc;
  }
  if (node["temperature"]) {
    if (auto k = quantity(node["temperature"], QuantityKind::kTemperature, "colour temperature",
                          Range{1000, 40000})) {
      light.temperature_k = *k;
    }
  }
  if (node["size"]) {
    const YAML::Node size = node["size"];
    if (!size.IsSequence() || size.size() != 2) {
      error(size, "area light size must be [width, height]");
    } else {
      auto w = quantity(size[0], QuantityKind::kLength, "area light width", Range{0.001, 20});
      auto h = quantity(size[1], QuantityKind::kLength, "area light height", Range{0.001, 20});
      if (w && h) light.size_m = {*w, *h};
    }
  } else if (light.type == ir::LightType::kArea) {
    error(node, "an area light needs a 'size' [width, height]");
  }
  if (light.type == ir::LightType::kSpot) {
    light.spot_angle_rad = 45 * kDeg;
    if (node["angle"]) {
      if (auto a = quantity(node["angle"], QuantityKind::kAngle, "spot angle",
                            Range{1 * kDeg, 180 * kDeg})) {
        light.spot_angle_rad = *a;
      }
    }
    if (node["blend"]) {
      if (auto b = quantity(node["blend"], QuantityKind::kNumber, "spot blend", Range{0, 1})) {
        light.spot_blend = *b;
      }
    }
  }
  scene.lights.push_back(light_spec);
}

void Checker::read_camera(const YAML::Node& node, spec::SceneSpec& scene) {
  ir::Camera& camera = scene.camera;
  camera.loc = loc(node);
  if (!expect_map(node, "camera")) return;
  check_keys(node,
             {"body", "sensor", "make", "model", "lens", "exposure", "focus", "white_balance",
              "effects", "output"},
             "camera");
  const bool has_body = static_cast<bool>(node["body"]);
  const bool has_sensor = static_cast<bool>(node["sensor"]);
  if (has_body && has_sensor) {
    error(node["sensor"], "give the camera either a 'body' preset or a 'sensor', not both");
  } else if (!has_body && !has_sensor) {
    error(node,
          "the camera needs a 'body' preset (e.g. canon-6d) or a 'sensor' {width, height, "
          "pixels}");
  }
  if (has_body) {
    if (auto name = scalar(node["body"], "body")) {
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
        std::string suggestion = closest_match(*name, names);
        std::string list;
        for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
        error(node["body"],
              fmt::format("unknown camera body '{}'{}", *name,
                          suggestion.empty() ? fmt::format(" (known: {})", list)
                                             : fmt::format("; did you mean '{}'?", suggestion)));
      }
    }
  }
  if (has_sensor) {
    const YAML::Node sensor = node["sensor"];
    camera.body = "custom";
    camera.make = "RigC";
    camera.model = "custom sensor";
    if (expect_map(sensor, "sensor")) {
      check_keys(sensor, {"width", "height", "pixels"}, "sensor");
      for (const char* key : {"width", "height", "pixels"}) {
        if (lacks(sensor, key)) error(sensor, fmt::format("sensor needs '{}'", key));
      }
      if (sensor["width"]) {
        if (auto v = quantity(sensor["width"], QuantityKind::kLength, "sensor width",
                              Range{0.001, 0.2})) {
          camera.sensor_width_m = *v;
        }
      }
      if (sensor["height"]) {
        if (auto v = quantity(sensor["height"], QuantityKind::kLength, "sensor height",
                              Range{0.001, 0.2})) {
          camera.sensor_height_m = *v;
        }
      }
      if (const YAML::Node pixels = sensor["pixels"]) {
        if (!pixels.IsSequence() || pixels.size() != 2) {
          error(pixels, "sensor pixels must be [width, height]");
        } else {
          auto w = integer(pixels[0], "sensor pixel width", 16, 20000);
          auto h = integer(pixels[1], "sensor pixel height", 16, 20000);
          if (w && h) {
            camera.width_px = *w;
            camera.height_px = *h;
          }
        }
      }
    }
  }
  // EXIF strings: a JPEG marker holds under 64 KB, and libjpeg ended the process ("Bogus marker
  // length") on a longer make or model.
  for (const auto& [key, field] : {std::pair{"make", &camera.make}, {"model", &camera.model}}) {
    if (!node[key]) continue;
    if (auto v = scalar(node[key], key)) {
      // EXIF text is NUL-terminated: a "\0" cut the tag short without a word.
      const bool control =
          std::any_of(v->begin(), v->end(), [](unsigned char c) { return c < 0x20 || c == 0x7F; });
      if (v->size() > kMaxExifText) {
        error(node[key],
              fmt::format("camera {} is {} bytes long; at most {}", key, v->size(), kMaxExifText));
      } else if (control) {
        error(node[key], fmt::format("camera {} holds a control character (EXIF text is one line "
                                     "of printable characters)",
                                     key));
      } else {
        *field = *v;
      }
    }
  }
  if (const YAML::Node lens = node["lens"]) {
    if (expect_map(lens, "lens")) {
      check_keys(lens, {"focal_length", "distortion", "vignetting"}, "lens");
      if (lens["focal_length"]) {
        if (auto f = quantity(lens["focal_length"], QuantityKind::kLength, "focal length",
                              Range{0.004, 1.2})) {
          camera.focal_length_m = *f;
        }
      } else if (lacks(lens, "focal_length")) {
        error(lens, "lens needs a 'focal_length' (e.g. 50mm)");
      }
      if (const YAML::Node distortion = lens["distortion"]) {
        if (expect_map(distortion, "distortion")) {
          camera.distortion_loc = loc(distortion);
          check_keys(distortion, {"k1", "k2", "k3", "p1", "p2"}, "distortion");
          auto read = [&](const char* key, double& out) {
            if (!distortion[key]) return;
            if (auto v = quantity(distortion[key], QuantityKind::kNumber, key, Range{-1, 1})) {
              out = *v;
            }
          };
          read("k1", camera.distortion.k1);
          read("k2", camera.distortion.k2);
          read("k3", camera.distortion.k3);
          read("p1", camera.distortion.p1);
          read("p2", camera.distortion.p2);
        }
      }
      if (lens["vignetting"]) {
        if (auto v =
                quantity(lens["vignetting"], QuantityKind::kNumber, "vignetting", Range{0, 0.95})) {
          camera.vignetting = *v;
        }
      }
    }
  } else {
    error(node, "the camera needs a 'lens' with a focal_length");
  }
  if (const YAML::Node exposure = node["exposure"]) {
    if (expect_map(exposure, "exposure")) {
      check_keys(exposure, {"aperture", "shutter", "iso"}, "exposure");
      for (const char* key : {"aperture", "shutter", "iso"}) {
        if (lacks(exposure, key)) error(exposure, fmt::format("exposure needs '{}'", key));
      }
      // The ranges of ISO 12232 stops that the seed paper's DSLR model offers.
      if (exposure["aperture"]) camera.aperture_loc = loc(exposure["aperture"]);
      if (exposure["shutter"]) camera.shutter_loc = loc(exposure["shutter"]);
      if (exposure["iso"]) camera.iso_loc = loc(exposure["iso"]);
      if (exposure["aperture"]) {
        if (auto v = quantity(exposure["aperture"], QuantityKind::kFNumber, "aperture",
                              Range{1.2, 64})) {
          camera.aperture_f_number = *v;
        }
      }
      if (exposure["shutter"]) {
        if (auto v = quantity(exposure["shutter"], QuantityKind::kTime, "shutter",
                              Range{1.0 / 8000, 30})) {
          camera.shutter_s = *v;
        }
      }
      if (exposure["iso"]) {
        if (auto v = quantity(exposure["iso"], QuantityKind::kNumber, "ISO", Range{100, 51200})) {
          camera.iso = *v;
        }
      }
    }
  } else {
    error(node, "the camera needs an 'exposure' {aperture, shutter, iso}");
  }
  if (const YAML::Node focus = node["focus"]) {
    camera.focus_loc = loc(focus);
    if (focus.IsScalar() && focus.Scalar() == "auto") {
      scene.focus_auto = true;
    } else if (auto d =
                   quantity(focus, QuantityKind::kLength, "focus distance", Range{0.01, 1000})) {
      scene.focus_auto = false;
      scene.focus_distance_m = *d;
    }
  }
  if (const YAML::Node wb = node["white_balance"]) {
    if (wb.IsScalar() && wb.Scalar() == "auto") {
      camera.white_balance = ir::WhiteBalanceMode::kAuto;
    } else if (auto k =
                   quantity(wb, QuantityKind::kTemperature, "white balance", Range{2000, 12000})) {
      camera.white_balance = ir::WhiteBalanceMode::kKelvin;
      camera.white_balance_k = *k;
    }
  }
  if (const YAML::Node effects = node["effects"]) {
    if (expect_map(effects, "effects")) {
      check_keys(
          effects,
          {"depth_of_field", "diffraction", "motion_blur", "distortion", "vignetting", "noise"},
          "effects");
      auto read = [&](const char* key, bool& out) {
        if (!effects[key]) return;
        if (auto v = boolean(effects[key], key)) out = *v;
      };
      read("depth_of_field", camera.effects.depth_of_field);
      read("diffraction", camera.effects.diffraction);
      read("motion_blur", camera.effects.motion_blur);
      read("distortion", camera.effects.distortion);
      read("vignetting", camera.effects.vignetting);
      read("noise", camera.effects.noise);
    }
  }
  if (const YAML::Node output = node["output"]) {
    if (expect_map(output, "output")) {
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
      if (output["quality"]) {
        if (auto q = integer(output["quality"], "JPEG quality", 1, 100)) camera.jpeg_quality = *q;
      }
    }
  }
  // Acceptable circle of confusion: the sensor diagonal / 1500 (0.029 mm for full frame).
  camera.circle_of_confusion_m = std::hypot(camera.sensor_width_m, camera.sensor_height_m) / 1500.0;
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
  group.kind = ir::ShotKind::kTurntable;
  spec::TurntableShotsSpec& shots = group.turntable;
  if (!expect_map(node, "turntable shots")) return;
  check_keys(node, {"steps", "step", "start", "speed", "camera"}, "turntable shots");
  if (node["steps"]) {
    if (auto n = integer(node["steps"], "turntable steps", 1, 3600)) shots.steps = *n;
  }
  if (node["step"]) {
    if (auto a = quantity(node["step"], QuantityKind::kAngle, "turntable step",
                          Range{-360 * kDeg, 360 * kDeg})) {
      shots.step_rad = *a;
    }
  } else {
    shots.step_rad = 2 * std::numbers::pi / shots.steps;
  }
  if (node["start"]) {
    if (auto a = quantity(node["start"], QuantityKind::kAngle, "turntable start",
                          Range{-360 * kDeg, 360 * kDeg})) {
      shots.start_rad = *a;
    }
  }
  if (node["speed"]) {
    if (auto w = quantity(node["speed"], QuantityKind::kAngularVelocity, "turntable speed",
                          Range{-100, 100})) {
      shots.speed_rad_s = *w;
    }
  }
  if (const YAML::Node camera = node["camera"]) {
    if (expect_map(camera, "turntable camera")) {
      check_keys(camera, {"distance", "height", "azimuth", "aim"}, "turntable camera");
      if (camera["distance"]) {
        if (auto d = quantity(camera["distance"], QuantityKind::kLength, "camera distance",
                              Range{0.01, 1000})) {
          shots.camera.distance_m = *d;
        }
      }
      if (camera["height"]) {
        if (auto h = quantity(camera["height"], QuantityKind::kLength, "camera height",
                              Range{-100, 100})) {
          shots.camera.height_m = *h;
        }
      }
      if (camera["azimuth"]) {
        if (auto a = quantity(camera["azimuth"], QuantityKind::kAngle, "camera azimuth",
                              Range{-360 * kDeg, 360 * kDeg})) {
          shots.camera.azimuth_rad = *a;
        }
      }
      if (camera["aim"]) {
        if (auto t = target(camera["aim"], "aim")) shots.camera.aim = *t;
      }
    }
  } else {
    error(node, "turntable shots need a 'camera' {distance, height}");
  }
}

void Checker::read_orbit_shots(const YAML::Node& node, spec::ShotGroupSpec& group) {
  group.kind = ir::ShotKind::kOrbit;
  spec::OrbitShotsSpec& orbit = group.orbit;
  if (!expect_map(node, "orbit shots")) return;
  check_keys(node, {"rings", "distance", "aim"}, "orbit shots");
  if (node["distance"]) {
    if (auto d = quantity(node["distance"], QuantityKind::kLength, "orbit distance",
                          Range{0.01, 1000})) {
      orbit.distance_m = *d;
    }
  } else {
    error(node, "orbit shots need a 'distance' from the object");
  }
  if (node["aim"]) {
    if (auto t = target(node["aim"], "aim")) orbit.aim = *t;
  }
  const YAML::Node rings = node["rings"];
  if (!rings || !rings.IsSequence() || rings.size() == 0) {
    error(rings ? rings : node, "orbit shots need 'rings': a list of {elevation, count}");
    return;
  }
  for (const auto& ring_node : rings) {
    spec::RingSpec ring;
    ring.loc = loc(ring_node);
    if (!expect_map(ring_node, "a ring")) continue;
    check_keys(ring_node, {"elevation", "count", "start"}, "a ring");
    if (ring_node["elevation"]) {
      if (auto e = quantity(ring_node["elevation"], QuantityKind::kAngle, "ring elevation",
                            Range{-90 * kDeg, 90 * kDeg})) {
        ring.elevation_rad = *e;
      }
    }
    if (ring_node["count"]) {
      if (auto n = integer(ring_node["count"], "ring count", 1, 3600)) ring.count = *n;
    } else {
      error(ring_node, "a ring needs a 'count' of shots");
    }
    if (ring_node["start"]) {
      if (auto a = quantity(ring_node["start"], QuantityKind::kAngle, "ring start",
                            Range{-360 * kDeg, 360 * kDeg})) {
        ring.start_rad = *a;
      }
    }
    orbit.rings.push_back(ring);
  }
}

void Checker::read_pose_shot(const YAML::Node& node, spec::ShotGroupSpec& group) {
  group.kind = ir::ShotKind::kPose;
  spec::PoseShotSpec& pose = group.pose;
  if (!expect_map(node, "a pose shot")) return;
  check_keys(node, {"position", "look_at", "up", "turntable"}, "a pose shot");
  if (node["position"]) {
    if (auto p = vec3(node["position"], QuantityKind::kLength, "camera position")) {
      pose.position = *p;
    }
  } else {
    error(node, "a pose shot needs a 'position'");
  }
  pose.look_at.loc = loc(node);
  if (node["look_at"]) {
    if (auto t = target(node["look_at"], "look_at")) pose.look_at = *t;
  }
  if (node["up"]) {
    if (auto u = vec3(node["up"], QuantityKind::kNumber, "up")) {
      if (u->stableNorm() < 1e-9)
        error(node["up"], "up must not be zero");
      else
        pose.up = u->stableNormalized();
    }
  }
  if (node["turntable"]) {
    if (auto a = quantity(node["turntable"], QuantityKind::kAngle, "turntable angle",
                          Range{-360 * kDeg, 360 * kDeg})) {
      pose.turntable_rad = *a;
    }
  }
}

// Whether `text` is well-formed UTF-8 (no overlong forms, surrogates or code points past
// U+10FFFF).
bool valid_utf8(const std::string& text) {
  const auto* p = reinterpret_cast<const unsigned char*>(text.data());
  const auto* end = p + text.size();
  while (p < end) {
    const unsigned char c = *p;
    int extra = 0;
    unsigned char low = 0x80, high = 0xBF;  // the first continuation byte's range
    if (c < 0x80) {
      ++p;
      continue;
    } else if (c >= 0xC2 && c <= 0xDF) {
      extra = 1;
    } else if (c >= 0xE0 && c <= 0xEF) {
      extra = 2;
      if (c == 0xE0) low = 0xA0;
      if (c == 0xED) high = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
      extra = 3;
      if (c == 0xF0) low = 0x90;
      if (c == 0xF4) high = 0x8F;
    } else {
      return false;
    }
    if (end - p <= extra || p[1] < low || p[1] > high) return false;
    for (int k = 2; k <= extra; ++k) {
      if (p[k] < 0x80 || p[k] > 0xBF) return false;
    }
    p += extra + 1;
  }
  return true;
}

// The mark of the first key or scalar value under `root` that is not UTF-8. yaml-cpp passes a
// Latin-1 byte through: `check` accepted "café" in Latin-1, and writing the IR or the manifest
// as JSON then failed (exit 2) after the images were written.
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

}  // namespace

std::optional<YAML::Node> parse_yaml(const std::string& text, const std::string& file,
                                     DiagnosticEngine& diag) {
  try {
    // Every document, so that a second one is an error rather than silently left unread.
    const std::vector<YAML::Node> documents = YAML::LoadAll(text);
    if (documents.size() > 1) {
      const YAML::Mark mark = documents[1].Mark();
      diag.error({file, std::max(mark.line, 0) + 1, std::max(mark.column, 0) + 1},
                 "a scene file holds one YAML document; a second one starts here");
      return std::nullopt;
    }
    const YAML::Node root = documents.empty() ? YAML::Node() : documents.front();
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
