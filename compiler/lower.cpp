#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <tuple>

#include "assets/mesh_io.h"
#include "assets/model_cache.h"
#include "assets/primitives.h"
#include "compiler/check.h"
#include "compiler/frontend.h"
#include "compiler/limits.h"
#include "ir/color.h"
#include "ir/utf8_text.h"

namespace rigc {
namespace {

namespace fs = std::filesystem;
using ir::Mat4;
using ir::Vec3;

Mat4 translation(const Vec3& t) {
  Mat4 m = Mat4::Identity();
  m.block<3, 1>(0, 3) = t;
  return m;
}

// Whether a mesh's vertex colours vary enough to be a texture SfM can match (a luminance spread
// of 0.02 in linear light, about 8 sRGB codes in mid tones), not one paint colour.
bool vertex_colors_vary(const ir::Mesh& mesh) {
  if (mesh.colors.size() < 2) return false;
  double sum = 0, sum_squares = 0;
  for (const Eigen::Vector3f& c : mesh.colors) {
    const double y = luminance(c.cast<double>());
    sum += y;
    sum_squares += y * y;
  }
  const double n = static_cast<double>(mesh.colors.size());
  const double variance = std::max(sum_squares / n - (sum / n) * (sum / n), 0.0);
  return std::sqrt(variance) >= 0.02;
}

Mat4 rotation(const Eigen::Matrix3d& r) {
  Mat4 m = Mat4::Identity();
  m.block<3, 3>(0, 0) = r;
  return m;
}

// Converts a file's up axis to RigC's +Z up (right-handed rotations only).
Eigen::Matrix3d up_axis_rotation(char axis, bool negative) {
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  if (axis == 'y') {
    // +Y up: (x, y, z) -> (x, -z, y); -Y up: (x, y, z) -> (x, z, -y).
    r << 1, 0, 0, 0, 0, negative ? 1 : -1, 0, negative ? -1 : 1, 0;
  } else if (axis == 'z' && negative) {
    r << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  }
  return r;
}

// Camera looking from `eye` at `target`, OpenCV axes (+X right, +Y down, +Z forward).
Mat4 look_at(const Vec3& eye, const Vec3& target, Vec3 up) {
  Vec3 forward = (target - eye).normalized();
  if (std::abs(forward.dot(up.normalized())) > 0.999) {
    up = std::abs(forward.y()) < 0.9 ? Vec3(0, 1, 0) : Vec3(1, 0, 0);
  }
  Vec3 right = forward.cross(up).normalized();
  Vec3 down = forward.cross(right);
  Mat4 m = Mat4::Identity();
  m.block<3, 1>(0, 0) = right;
  m.block<3, 1>(0, 1) = down;
  m.block<3, 1>(0, 2) = forward;
  m.block<3, 1>(0, 3) = eye;
  return m;
}

void transformed_bounds(const ir::Mesh& mesh, const Mat4& m, Vec3* lo, Vec3* hi) {
  *lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  *hi = -*lo;
  const Eigen::Matrix3d linear = m.block<3, 3>(0, 0);
  const Vec3 offset = m.block<3, 1>(0, 3);
  for (const auto& p : mesh.positions) {
    Vec3 q = linear * p.cast<double>() + offset;
    *lo = lo->cwiseMin(q);
    *hi = hi->cwiseMax(q);
  }
}

class Lowering {
 public:
  Lowering(const spec::SceneSpec& spec, DiagnosticEngine& diag) : spec_(spec), diag_(diag) {}

  std::optional<ir::Scene> run() {
    scene_.language_version = spec_.version;
    scene_.name = spec_.name;
    // The manifest and the IR are JSON: a file name that is not UTF-8 is kept readable instead.
    scene_.source_file = valid_utf8_text(spec_.source_file);
    scene_.studio = spec_.studio;
    scene_.camera = spec_.camera;
    scene_.coverage = spec_.coverage;
    if (!lower_object()) return std::nullopt;
    lower_camera();
    lower_lights();
    lower_shots();
    place_backdrop();
    if (errors_) return std::nullopt;
    return std::move(scene_);
  }

 private:
  void error(const SourceLoc& loc, std::string message) {
    diag_.error(loc, std::move(message));
    ++errors_;
  }

  bool lower_object();
  bool load_mesh(Eigen::Matrix3d* up);
  void apply_surface();
  bool place_object(const Eigen::Matrix3d& up);
  std::optional<double> fit_scale(const Vec3& extent);
  void warn_about_object();
  void lower_camera();
  void lower_lights();
  void lower_shots();
  void add_rotation_pose(const spec::PoseShotSpec& pose, const SourceLoc& loc);
  void place_backdrop();
  Vec3 aim_point(const spec::Target& target) const {
    if (!target.object) return target.point;
    return (ir::world_from_object(scene_, 0) * object_center_.homogeneous()).head<3>();
  }
  void add_shot(ir::ShotKind kind, const Mat4& world_from_camera, double angle, double velocity,
                const Vec3& aim, const SourceLoc& loc);
  bool too_many_shots_ = false;  // reported once

  const spec::SceneSpec& spec_;
  DiagnosticEngine& diag_;
  ir::Scene scene_;
  Vec3 object_center_{0, 0, 0};  // bounding-box centre, object frame
  int errors_ = 0;
};

bool Lowering::lower_object() {
  scene_.object.loc = spec_.object.loc;
  Eigen::Matrix3d up = Eigen::Matrix3d::Identity();
  if (!load_mesh(&up)) return false;
  apply_surface();
  if (!place_object(up)) return false;
  warn_about_object();
  return true;
}

// Loads the mesh file or builds the primitive; `up` turns a file's up axis to +Z.
bool Lowering::load_mesh(Eigen::Matrix3d* up) {
  const spec::ObjectSpec& object = spec_.object;
  ir::Object& out = scene_.object;
  if (!object.mesh_path) {
    auto kind = primitive_from_name(object.primitive->value);
    out.source = "primitive:" + object.primitive->value;
    out.mesh = make_primitive_cached(*kind, object.primitive_detail, object.primitive_seed);
    scene_.materials.push_back(ir::Material{});
    scene_.materials.back().name = object.primitive->value;
    return true;
  }
  std::string why;
  auto model = load_model_cached(object.mesh_path_resolved, &why);
  if (!model) {
    error(object.mesh_path->loc, fmt::format("cannot load mesh: {}", why));
    return false;
  }
  for (const std::string& warning : model->warnings) {
    diag_.warning(object.mesh_path->loc, warning);
  }
  out.source = object.mesh_path_resolved;
  out.mesh = std::move(model->mesh);
  out.mesh.colors = std::move(model->vertex_colors);
  scene_.materials = std::move(model->materials);
  scene_.textures = std::move(model->textures);
  std::string ext = fs::path(object.mesh_path_resolved).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  const bool gltf = ext == ".gltf" || ext == ".glb";
  if (gltf && object.up_axis) {
    diag_.warning(object.mesh_path->loc,
                  "glTF files are always +Y up and converted automatically; 'up' is ignored");
  } else if (!gltf) {
    // Scans and DCC exports in OBJ/PLY are usually +Y up; STL (CAD) is usually +Z up.
    char axis = object.up_axis ? object.up_axis : (ext == ".stl" ? 'z' : 'y');
    *up = up_axis_rotation(axis, object.up_negative);
  }
  return true;
}

// The scene's surface settings over every material (a texture wins over the pattern). A mesh's
// vertex colours stay its base colour unless the scene gives one or a material has an image
// texture: then every material keeps the mean vertex colour it loaded with.
void Lowering::apply_surface() {
  const spec::ObjectSpec& object = spec_.object;
  bool textured = false;
  for (auto& material : scene_.materials) {
    material.loc = object.loc;
    if (object.surface_color) material.base_color = *object.surface_color;
    if (object.roughness) material.roughness = *object.roughness;
    if (object.metallic) material.metallic = *object.metallic;
    if (material.base_color_texture < 0) material.pattern = object.pattern;
    textured |= material.base_color_texture >= 0;
  }
  if (object.surface_color || textured) scene_.object.mesh.colors.clear();
  if (scene_.materials.empty()) scene_.materials.push_back(ir::Material{});
}

// Rotation and scale first, then fit to the requested size, then rest on the turntable.
bool Lowering::place_object(const Eigen::Matrix3d& up) {
  const spec::ObjectSpec& object = spec_.object;
  ir::Object& out = scene_.object;
  Eigen::Matrix3d user_rotation = (Eigen::AngleAxisd(object.rotate_rad.z(), Vec3::UnitZ()) *
                                   Eigen::AngleAxisd(object.rotate_rad.y(), Vec3::UnitY()) *
                                   Eigen::AngleAxisd(object.rotate_rad.x(), Vec3::UnitX()))
                                      .toRotationMatrix();
  Mat4 user_scale = Mat4::Identity();
  user_scale.diagonal().head<3>() = object.scale;
  Mat4 shaped = rotation(user_rotation) * user_scale * rotation(up);
  Vec3 lo, hi;
  transformed_bounds(out.mesh, shaped, &lo, &hi);
  const std::optional<double> fit = fit_scale(hi - lo);
  if (!fit) return false;
  Mat4 scaled = Mat4::Identity();
  scaled.block<3, 3>(0, 0) *= *fit;
  shaped = scaled * shaped;
  transformed_bounds(out.mesh, shaped, &lo, &hi);
  const Vec3 rest_on_table(-(lo.x() + hi.x()) / 2, -(lo.y() + hi.y()) / 2, -lo.z());
  out.object_from_mesh = translation(rest_on_table + object.translate) * shaped;
  transformed_bounds(out.mesh, out.object_from_mesh, &out.bounds_min_object,
                     &out.bounds_max_object);
  // An object a camera can photograph: not of zero size (`scale: 1e-300`), nor beyond any float
  // (`translate: [1e300m, 0, 0]`).
  const double size_m = (out.bounds_max_object - out.bounds_min_object).maxCoeff();
  const double offset_m =
      out.bounds_min_object.cwiseAbs().cwiseMax(out.bounds_max_object.cwiseAbs()).maxCoeff();
  if (!(size_m >= limits::kObjectSmallestM && size_m <= limits::kObjectLargestM &&
        offset_m <= limits::kObjectReachM)) {
    error(object.loc, fmt::format("the object is {:.3g} m across and reaches {:.3g} m from the "
                                  "table's centre after fit, scale and translate; it must be "
                                  "{:g} mm to {:g} m across and within {:g} km",
                                  size_m, offset_m, limits::kObjectSmallestM * 1000,
                                  limits::kObjectLargestM, limits::kObjectReachM / 1000));
    return false;
  }
  object_center_ = (out.bounds_min_object + out.bounds_max_object) / 2;
  return true;
}

// The factor that gives the shaped object (of `extent`) the size its fit asks for: 1 without
// a fit; nullopt (reported) when it cannot be fitted.
std::optional<double> Lowering::fit_scale(const Vec3& extent) {
  const spec::ObjectSpec& object = spec_.object;
  if (!(extent.maxCoeff() > 0) || !extent.allFinite()) {
    error(object.loc, "the object's mesh has no extent (all vertices at one point)");
    return std::nullopt;
  }
  if (object.fit_height) {
    if (extent.z() <= 0) {
      error(object.fit_height->loc, "cannot fit the height of a flat object (no extent in z)");
      return std::nullopt;
    }
    return object.fit_height->value / extent.z();
  }
  if (object.fit_width) return object.fit_width->value / std::max(extent.x(), extent.y());
  if (object.fit_size) return object.fit_size->value / extent.maxCoeff();
  return 1.0;
}

// An object that overhangs the turntable, or that offers SfM no texture.
void Lowering::warn_about_object() {
  const ir::Object& out = scene_.object;
  const double radius = (out.bounds_max_object - out.bounds_min_object).head<2>().norm() / 2;
  if (radius > scene_.studio.turntable.diameter_m / 2 * 1.5) {
    diag_.warning(out.loc,
                  fmt::format("the object ({:.0f} cm across) overhangs the {:.0f} cm turntable",
                              radius * 200, scene_.studio.turntable.diameter_m * 100));
  }
  bool textured = vertex_colors_vary(out.mesh);
  for (const auto& m : scene_.materials) {
    textured |= m.base_color_texture >= 0 || m.pattern.kind != ir::PatternKind::kNone;
  }
  if (!textured) {
    // At the surface that has no pattern, when the scene writes one.
    const SourceLoc& surface = spec_.object.surface_loc;
    diag_.warning(surface.line > 0 ? surface : out.loc,
                  "the object has no texture and no surface pattern: SfM will find few features; "
                  "add surface: {pattern: speckle}");
  }
}

// Why the Brown-Conrady mapping `d` is no lens over a sensor of half-extents (x, y) in
// normalised coordinates (empty if it is one): walking out from the centre along every
// direction, the mapping must stay one-to-one (a positive Jacobian) until it leaves the sensor,
// and it must leave it. Each coefficient alone may lie in -1..1, but k1 = -1 folds a 50 mm
// lens's frame over before its corners, and all five at +1 smear the image beyond recognition,
// while cameras.txt would export the mapping as the truth.
std::string distortion_problem(const ir::Distortion& d, double half_x, double half_y) {
  if (d.is_zero()) return {};
  constexpr int kDirections = 256;
  const double corner = std::hypot(half_x, half_y);
  const double step = corner / 512, farthest = 8 * corner;
  for (int k = 0; k < kDirections; ++k) {
    const double angle = 2 * std::numbers::pi * (k + 0.5) / kDirections;
    const double cx = std::cos(angle), cy = std::sin(angle);
    bool left = false;
    for (double r = step; r <= farthest && !left; r += step) {
      const ir::Vec2 distorted = d.apply(r * cx, r * cy);
      if (!(d.jacobian(r * cx, r * cy).determinant() > 0)) {
        return fmt::format(
            "the distortion folds the image over {:.0f} % of the way to the frame's corner: "
            "no lens maps it; make the coefficients smaller",
            100 * distorted.norm() / corner);
      }
      left = std::abs(distorted.x()) > half_x || std::abs(distorted.y()) > half_y;
    }
    if (!left) {
      return "the distortion pulls the frame's edge in so far that no scene point reaches it; "
             "make the coefficients smaller";
    }
  }
  return {};
}

void Lowering::lower_camera() {
  ir::Camera& camera = scene_.camera;
  if (const auto& given = spec_.intrinsics) {
    // Measured intrinsics are the truth: kept as given, not recomputed from the focal length.
    camera.fx = given->fx;
    camera.fy = given->fy;
    camera.cx = given->cx;
    camera.cy = given->cy;
  } else {
    camera.fx = camera.focal_length_m * camera.width_px / camera.sensor_width_m;
    camera.fy = camera.focal_length_m * camera.height_px / camera.sensor_height_m;
    camera.cx = camera.width_px / 2.0;
    camera.cy = camera.height_px / 2.0;
  }
  // The frame's farther edge from the principal point on each axis, in normalised coordinates.
  const double half_x = std::max(camera.cx, camera.width_px - camera.cx) / camera.fx;
  const double half_y = std::max(camera.cy, camera.height_px - camera.cy) / camera.fy;
  // With the effect off the mapping is neither rendered nor exported.
  const std::string lens_problem = camera.effects.distortion
                                       ? distortion_problem(camera.distortion, half_x, half_y)
                                       : std::string();
  if (!lens_problem.empty()) error(camera.distortion_loc, lens_problem);
  // The photographer's acceptable circle of confusion unless the scene sets its own.
  if (scene_.coverage.max_blur_px <= 0) {
    scene_.coverage.max_blur_px =
        camera.circle_of_confusion_m / (camera.sensor_width_m / camera.width_px);
  }
}

void Lowering::lower_lights() {
  for (const auto& light_spec : spec_.lights) {
    ir::Light light = light_spec.light;
    light.color = blackbody_linear_srgb(light.temperature_k);
    if (light_spec.look_at) {
      Vec3 direction = aim_point(*light_spec.look_at) - light.position;
      if (direction.norm() < 1e-9) {
        error(light.loc, "the light is at the point it looks at; move it or give a direction");
        continue;
      }
      light.direction = direction.normalized();
    }
    scene_.studio.lights.push_back(light);
  }
}

void Lowering::add_shot(ir::ShotKind kind, const Mat4& world_from_camera, double angle,
                        double velocity, const Vec3& aim, const SourceLoc& loc) {
  if (scene_.shots.size() >= limits::kMostShots) {
    if (!too_many_shots_) {
      error(loc, fmt::format("the shots make more than {} photos", limits::kMostShots));
    }
    too_many_shots_ = true;
    return;
  }
  ir::Shot shot;
  shot.index = static_cast<int>(scene_.shots.size());
  shot.name = fmt::format("shot_{:03d}", shot.index);
  shot.kind = kind;
  shot.world_from_camera = world_from_camera;
  shot.turntable_angle_rad = angle;
  shot.turntable_velocity_rad_s = velocity;
  shot.loc = loc;
  shot.object_from_camera = ir::world_from_object(scene_, angle).inverse() * world_from_camera;
  const Vec3 eye = world_from_camera.block<3, 1>(0, 3);
  const Vec3 forward = world_from_camera.block<3, 1>(0, 2);
  const double camera_space_depth = (aim - eye).dot(forward);
  shot.focus_distance_m = spec_.focus_auto ? camera_space_depth : spec_.focus_distance_m;
  const double f = scene_.camera.focal_length_m;
  if (shot.focus_distance_m <= f * 1.01) {
    error(spec_.focus_auto ? loc : scene_.camera.focus_loc,
          fmt::format("{}: focus distance {:.3f} m is not beyond the focal length {:.0f} mm",
                      shot.name, shot.focus_distance_m, f * 1000));
  } else if (spec_.focus_auto && shot.focus_distance_m < spec_.lens_min_focus_m) {
    error(loc,
          fmt::format("{}: the subject is {:.2f} m away, closer than the lens {} focuses "
                      "({:g} m at the closest); step back",
                      shot.name, shot.focus_distance_m, spec_.lens_preset, spec_.lens_min_focus_m));
  }
  const Vec3 half = (scene_.object.bounds_max_object - scene_.object.bounds_min_object) / 2;
  const Vec3 eye_in_object = shot.object_from_camera.block<3, 1>(0, 3) - object_center_;
  if ((eye_in_object.cwiseAbs() - half).maxCoeff() < 0) {
    error(loc, fmt::format("{}: the camera is inside the object's bounding box", shot.name));
  }
  // Below the floor or inside the turntable's disc the camera sees nothing. The thin stand under
  // the disc is left out.
  const ir::Turntable& table = scene_.studio.turntable;
  if (eye.z() < 0) {
    error(loc, fmt::format("{}: the camera is {:.2f} m below the floor", shot.name, -eye.z()));
  } else if (eye.head<2>().norm() < table.diameter_m / 2 && eye.z() <= table.height_m &&
             eye.z() >= table.height_m - table.thickness_m) {
    error(loc, fmt::format("{}: the camera is inside the turntable's disc", shot.name));
  }
  scene_.shots.push_back(shot);
}

void Lowering::lower_shots() {
  const double table_top = scene_.studio.turntable.height_m;
  for (const auto& group : spec_.shots) {
    switch (group.kind) {
      case ir::ShotKind::kTurntable: {
        const auto& tt = group.turntable;
        const Vec3 eye(tt.camera.distance_m * std::cos(tt.camera.azimuth_rad),
                       tt.camera.distance_m * std::sin(tt.camera.azimuth_rad),
                       table_top + tt.camera.height_m);
        // The default aim is on the turntable axis at the object's mid height, so that the
        // object stays centred while it turns.
        Vec3 aim = aim_point(tt.camera.aim);
        if (tt.camera.aim.object) aim.head<2>().setZero();
        if ((aim - eye).norm() < 1e-6) {
          // As for a pose: the camera would get an arbitrary orientation.
          error(tt.camera.aim.loc.line > 0 ? tt.camera.aim.loc : group.loc,
                "the turntable camera's aim is the camera's own position");
          break;
        }
        const Mat4 world_from_camera = look_at(eye, aim, Vec3::UnitZ());
        for (int i = 0; i < tt.steps; ++i) {
          add_shot(ir::ShotKind::kTurntable, world_from_camera, tt.start_rad + i * tt.step_rad,
                   tt.speed_rad_s, aim, group.loc);
        }
        break;
      }
      case ir::ShotKind::kOrbit: {
        const Vec3 aim = aim_point(group.orbit.aim);
        for (const auto& ring : group.orbit.rings) {
          for (int i = 0; i < ring.count; ++i) {
            const double azimuth = ring.start_rad + 2 * std::numbers::pi * i / ring.count;
            const Vec3 offset(std::cos(ring.elevation_rad) * std::cos(azimuth),
                              std::cos(ring.elevation_rad) * std::sin(azimuth),
                              std::sin(ring.elevation_rad));
            const Vec3 eye = aim + group.orbit.distance_m * offset;
            add_shot(ir::ShotKind::kOrbit, look_at(eye, aim, Vec3::UnitZ()), 0, 0, aim, ring.loc);
          }
        }
        break;
      }
      case ir::ShotKind::kPose: {
        const auto& pose = group.pose;
        if (pose.camera_from_world) {
          add_rotation_pose(pose, group.loc);
          break;
        }
        const Vec3 aim = aim_point(pose.look_at);
        if ((aim - pose.position).norm() < 1e-6) {
          error(group.loc, "a pose's position and look_at are the same point");
          break;
        }
        add_shot(ir::ShotKind::kPose, look_at(pose.position, aim, pose.up), pose.turntable_rad, 0,
                 aim, group.loc);
        break;
      }
    }
  }
}

// A pose given by COLMAP's camera_from_world rotation and the camera centre, both in the world
// frame whatever the turntable angle (which turns the object, not the camera, as for look_at).
// `focus: auto` focuses at the object's centre's depth.
void Lowering::add_rotation_pose(const spec::PoseShotSpec& pose, const SourceLoc& loc) {
  Mat4 world_from_camera = Mat4::Identity();
  world_from_camera.block<3, 3>(0, 0) = pose.camera_from_world->transpose();
  world_from_camera.block<3, 1>(0, 3) = pose.position;
  add_shot(ir::ShotKind::kPose, world_from_camera, pose.turntable_rad, 0, aim_point(spec::Target{}),
           loc);
}

void Lowering::place_backdrop() {
  // The backdrop hangs behind the object, facing the cameras' mean horizontal direction.
  Vec3 mean_view = Vec3::Zero();
  for (const auto& shot : scene_.shots) mean_view += shot.world_from_camera.block<3, 1>(0, 2);
  mean_view.z() = 0;
  ir::Backdrop& backdrop = scene_.studio.backdrop;
  // A full orbit has no mean direction: the backdrop then stays on the +Y side.
  backdrop.direction =
      mean_view.norm() > 0.3 * scene_.shots.size() ? mean_view.normalized() : Vec3(0, 1, 0);
  if (!spec_.backdrop_distance_set) {
    // Behind every camera's horizontal distance, so no camera stands behind the screen.
    double farthest_camera = 0;
    for (const auto& shot : scene_.shots) {
      farthest_camera = std::max(farthest_camera, shot.world_from_camera.block<2, 1>(0, 3).norm());
    }
    backdrop.distance_m = std::clamp(farthest_camera + 0.3, 0.3, 20.0);
  }
}

}  // namespace

std::optional<ir::Scene> lower_scene(const spec::SceneSpec& scene, DiagnosticEngine& diag) {
  return Lowering(scene, diag).run();
}

}  // namespace rigc
