#include "twin/scene_text.h"

#include <fmt/format.h>

#include <cctype>

namespace rigc::twin {

namespace {

std::string vec(const ir::Vec3& v, const char* unit = "") {
  return fmt::format("[{:.6g}{}, {:.6g}{}, {:.6g}{}]", v.x(), unit, v.y(), unit, v.z(), unit);
}

// A scene name RigC accepts: letters, digits, '-' and '_'.
std::string safe_name(const std::string& name) {
  std::string out;
  for (const unsigned char c : name)
    out += std::isalnum(c) || c == '-' || c == '_' ? static_cast<char>(c) : '-';
  return out.empty() ? "twin" : out;
}

std::string shot_line(const std::string& photo, const eval::ViewCamera& c, double table_height) {
  const Eigen::Matrix3d r = c.camera_from_world.topLeftCorner<3, 3>();
  const ir::Vec3 position = c.center() + ir::Vec3(0, 0, table_height);
  std::string rows;
  for (int i = 0; i < 3; ++i) {
    rows += fmt::format("{}[{:.12g}, {:.12g}, {:.12g}]", i ? ", " : "", r(i, 0), r(i, 1), r(i, 2));
  }
  // Photo names are written as comments only: a '#' or a newline in one cannot reach the YAML.
  std::string name;
  for (const char ch : photo) name += (ch == '\n' || ch == '\r') ? ' ' : ch;
  return fmt::format(
      "  # {}\n  - pose: {{position: [{:.9g}m, {:.9g}m, {:.9g}m], rotation: [{}]}}\n", name,
      position.x(), position.y(), position.z(), rows);
}

}  // namespace

std::string scene_yaml(const TwinScene& t) {
  std::string y;
  y +=
      fmt::format("# The digital twin of a real capture, made by `rigc twin` from {}.\n", t.source);
  y += "# Object: the photos' silhouettes carved into a visual hull, coloured from the photos "
       "(their\n";
  y += "# lighting is in those colours). Camera and shots: the real ones, exactly. Studio: a "
       "guess\n";
  y += "# to edit (docs/twin.md says what a hull and this guess miss).\n";
  y += "rigc: 1\n";
  y += fmt::format("name: {}\n", safe_name(t.name));
  y += "object:\n";
  y += fmt::format("  mesh: {}\n", t.mesh_file);
  y += "  up: z   # written +Z up, in metres, resting on z = 0\n";
  y += fmt::format("  # {:.1f} x {:.1f} x {:.1f} cm\n", 100 * t.object_size.x(),
                   100 * t.object_size.y(), 100 * t.object_size.z());
  y +=
      "  surface: {pattern: none, roughness: 0.8}   # the colour is the mesh's (from the photos)\n";
  y += "studio:\n";
  y += "  # Hidden under the object, in the backdrop's colour: the photos' stand, not a "
       "turntable.\n";
  y += fmt::format("  turntable: {{diameter: {:.4g}m, height: {:.4g}m, color: {}}}\n",
                   t.table_diameter_m, t.table_height_m, vec(t.backdrop_linear));
  y += "  # The backdrop's colour as the photos show it around the object (linear RGB).\n";
  y += fmt::format("  backdrop: {{green_screen: {{color: {}}}}}\n", vec(t.backdrop_linear));
  y += fmt::format("  floor: {{color: {}}}   # as the backdrop: cameras all round see it too\n",
                   vec(t.backdrop_linear));
  y += "  lights:\n";
  y += "    # A guess: a key from the cameras' side and ambient fill (85 % of the light, as the\n";
  y +=
      "    # photos' shading is in the colours), scaled so that the twin's renders are as bright\n";
  y += "    # as the photos. Replace it with the studio's real lights.\n";
  y += fmt::format(
      "    - {{type: area, position: {}, size: [50cm, 50cm], power: {:.4g}W, temperature: 5500K, "
      "look_at: object}}\n",
      vec(t.lights.key_position, "m"), t.lights.key_power_w);
  y += fmt::format("  ambient: {:.4g}lx\n", t.lights.ambient_lux);
  y += "camera:\n";
  y += "  # The photos' camera by its calibration (pixels; COLMAP's PINHOLE).\n";
  y += fmt::format(
      "  intrinsics: {{width: {}, height: {}, fx: {:.9g}, fy: {:.9g}, cx: {:.9g}, cy: {:.9g}}}\n",
      t.camera.width, t.camera.height, t.camera.fx, t.camera.fy, t.camera.cx, t.camera.cy);
  y += "  exposure: {aperture: f/3.2, shutter: 1/30, iso: 100}\n";
  y += "  focus: auto\n";
  y += "  white_balance: 5500K\n";
  y += "shots:\n";
  y +=
      "  # The real cameras, one a photo: position (world frame) and COLMAP's camera_from_world.\n";
  for (const auto& [photo, camera] : t.shots) y += shot_line(photo, camera, t.table_height_m);
  return y;
}

}  // namespace rigc::twin
