// The checked scene description (the AST): what the user wrote, typed, in SI units, each part
// with its source location. Lowering resolves it into the IR (loads meshes, expands shots).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "compiler/diagnostics.h"
#include "ir/ir.h"

namespace rigc::spec {

template <typename T>
struct Located {
  T value{};
  SourceLoc loc;
};

// A point to aim at: the object's centre or an explicit world position.
struct Target {
  bool object = true;
  ir::Vec3 point{0, 0, 0};
  SourceLoc loc;
};

struct ObjectSpec {
  std::optional<Located<std::string>> mesh_path;  // as written; resolved against the scene folder
  std::string mesh_path_resolved;
  std::optional<Located<std::string>> primitive;  // sphere, box, cylinder, statue
  int primitive_detail = 5;
  std::uint32_t primitive_seed = 1;
  char up_axis = 0;  // 'y' or 'z' (0: the format's default)
  bool up_negative = false;
  // fit: at most one of these, the object's extent along that axis after rotation.
  std::optional<Located<double>> fit_height, fit_width, fit_size;
  ir::Vec3 scale{1, 1, 1};
  ir::Vec3 rotate_rad{0, 0, 0};  // XYZ Euler angles, applied x, then y, then z
  ir::Vec3 translate{0, 0, 0};   // added after the object is set on the turntable
  ir::SurfacePattern pattern;
  std::optional<ir::Vec3> surface_color;
  std::optional<double> roughness, metallic;
  SourceLoc loc;
  SourceLoc surface_loc;  // the `surface:` key, when written
};

struct TurntableCameraSpec {
  double distance_m = 0.8;                   // horizontal, from the turntable axis
  double height_m = 0.2;                     // above the turntable top
  double azimuth_rad = -1.5707963267948966;  // where the camera stands; -90deg is the -Y side
  Target aim;
};

struct TurntableShotsSpec {
  int steps = 18;
  double step_rad = 0.3490658503988659;
  double start_rad = 0;
  double speed_rad_s = 0;  // continuous rotation during exposures (motion blur)
  TurntableCameraSpec camera;
};

struct RingSpec {
  double elevation_rad = 0;
  int count = 12;
  double start_rad = -1.5707963267948966;
  SourceLoc loc;
};

struct OrbitShotsSpec {
  std::vector<RingSpec> rings;
  double distance_m = 0.8;  // from the aim point
  Target aim;
};

struct PoseShotSpec {
  ir::Vec3 position{0, -1, 0};
  Target look_at;
  ir::Vec3 up{0, 0, 1};
  // COLMAP's camera_from_world rotation in the world frame, orthonormalised: given instead of
  // look_at (and up).
  std::optional<Eigen::Matrix3d> camera_from_world;
  double turntable_rad = 0;
};

struct ShotGroupSpec {
  ir::ShotKind kind = ir::ShotKind::kPose;
  TurntableShotsSpec turntable;
  OrbitShotsSpec orbit;
  PoseShotSpec pose;
  SourceLoc loc;
};

// A camera given by its intrinsics (`camera: {intrinsics: ...}`): pixels, as COLMAP states them.
struct IntrinsicsSpec {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::optional<double> pixel_pitch_m;
  SourceLoc loc;
};

struct LightSpec {
  ir::Light light;
  std::optional<Target> look_at;  // for spot/area lights: aim instead of a direction
};

struct SceneSpec {
  int version = 1;
  std::string name;
  std::string source_file;
  std::string base_dir;
  ObjectSpec object;
  ir::Studio studio;  // lights without resolved directions
  std::vector<LightSpec> lights;
  bool backdrop_distance_set = false;
  ir::Camera camera;  // intrinsics not yet computed, unless given:
  std::optional<IntrinsicsSpec> intrinsics;
  bool focus_auto = true;
  double focus_distance_m = 1;
  // The lens preset's closest focus, which `focus: auto` cannot go under; 0 without a preset.
  std::string lens_preset;
  double lens_min_focus_m = 0;
  std::vector<ShotGroupSpec> shots;
  ir::CoverageSettings coverage;
};

}  // namespace rigc::spec
