// The scene IR: what every backend reads, and nothing else. Plain data in SI units
// (meters, radians, seconds, kelvin, watts, lux). Frames are named explicitly:
//   mesh   - the coordinates of the model file;
//   object - rotates with the turntable: origin on the turntable axis at its top surface, +Z up;
//   world  - the studio: floor at z = 0, +Z up, right-handed, the turntable axis is the Z axis;
//   camera - OpenCV/COLMAP convention: +X right, +Y down, +Z forward (the viewing direction).
// A transform named a_from_b maps coordinates in frame b to frame a.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ir/source_location.h"

namespace rigc::ir {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat4 = Eigen::Matrix4d;

// Lumens per watt of radiant power: the photometric convention that light powers in watts follow
// here (as Blender's do), so 1 W/(m²·sr) of linear luminance is 683 cd/m².
inline constexpr double kLumensPerWatt = 683.0;

// An 8-bit image (sRGB-encoded colour, as stored in files), row-major, top row first.
struct Texture {
  std::string source;  // file it came from (or "file.glb#image3" for embedded images)
  int width = 0;
  int height = 0;
  int channels = 0;  // 1..4
  std::vector<std::uint8_t> pixels;
};

enum class PatternKind { kNone, kSpeckle, kNoise, kChecker };

// Procedural albedo modulation for untextured meshes (SfM needs texture to find features).
struct SurfacePattern {
  PatternKind kind = PatternKind::kNone;
  double scale_m = 0.002;  // feature size on the surface
  double contrast = 0.8;   // 0 = flat, 1 = black to full base colour
  std::uint32_t seed = 1;
};

struct Material {
  std::string name;
  Vec3 base_color{0.8, 0.8, 0.8};  // linear RGB, multiplied by the texture
  int base_color_texture = -1;     // index into Scene::textures, or -1
  double roughness = 0.7;
  double metallic = 0.0;
  SurfacePattern pattern;
  SourceLoc loc;
};

// Triangle mesh; all per-vertex arrays have the same length.
struct Mesh {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;  // unit length
  std::vector<Eigen::Vector2f> uvs;      // empty if the mesh has none; v = 0 at the image top
  // Linear RGB per vertex, empty if none: where present it is the base colour, interpolated over
  // each triangle, in place of its material's (docs/surface-functions.md).
  std::vector<Eigen::Vector3f> colors;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<std::int32_t> triangle_material;  // one per triangle, index into Scene::materials
};

struct Object {
  std::string source;                        // mesh path as resolved, or "primitive:statue" etc.
  Mesh mesh;                                 // in the mesh frame
  Mat4 object_from_mesh = Mat4::Identity();  // fit, scale, rotate, translate, resting on the table
  Vec3 bounds_min_object{0, 0, 0};           // axis-aligned bounds in the object frame
  Vec3 bounds_max_object{0, 0, 0};
  SourceLoc loc;
};

struct Turntable {
  double diameter_m = 0.4;
  double height_m = 0.75;        // top surface above the floor
  double thickness_m = 0.03;     // of the disc
  Vec3 color{0.18, 0.18, 0.18};  // linear RGB albedo
  SourceLoc loc;
};

struct Backdrop {
  bool green_screen = true;
  Vec3 color{0.0, 0.69, 0.25};  // linear RGB albedo
  double distance_m = 1.0;      // from the turntable axis to the backdrop plane
  Vec3 direction{0, 1, 0};      // horizontal unit vector from the axis to the backdrop's centre
  double width_m = 3.0;
  double height_m = 2.5;
  SourceLoc loc;
};

enum class LightType { kPoint, kSpot, kDirectional, kArea };

struct Light {
  LightType type = LightType::kPoint;
  Vec3 position{0, 0, 0};     // world (not used by directional)
  Vec3 direction{0, 0, -1};   // unit, the way light travels (spot, directional, area)
  double power_w = 0;         // radiant power in Blender's convention (point, spot, area)
  double illuminance_lx = 0;  // directional only: illuminance on a surface facing the light
  double temperature_k = 6500;
  Vec3 color{1, 1, 1};        // linear RGB of the blackbody, normalised to luminance 1
  Vec2 size_m{0, 0};          // area light width and height
  double spot_angle_rad = 0;  // full cone angle
  double spot_blend = 0.15;   // 0 hard edge .. 1 soft
  SourceLoc loc;
};

struct Studio {
  Turntable turntable;
  Backdrop backdrop;
  std::vector<Light> lights;
  double ambient_lx = 0;  // uniform illuminance from every direction (a white room)
  Vec3 floor_color{0.3, 0.3, 0.3};
};

// Brown-Conrady coefficients, OpenCV order: k1 k2 p1 p2 k3.
struct Distortion {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  bool is_zero() const { return k1 == 0 && k2 == 0 && p1 == 0 && p2 == 0 && k3 == 0; }
  // The distorted normalised point of the undistorted (x, y) (COLMAP's OPENCV model). The one
  // place the mapping is written: the lens's inversion and the compiler's fold-over check use it.
  Vec2 apply(double x, double y) const {
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
            y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
  }
  // d apply / d(x, y) at (x, y); symmetric.
  Eigen::Matrix2d jacobian(double x, double y) const {
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double dradial = k1 + r2 * (2 * k2 + 3 * k3 * r2);  // d radial / d r²
    const double jxx = radial + 2 * x * x * dradial + 2 * p1 * y + 6 * p2 * x;
    const double jxy = 2 * x * y * dradial + 2 * p1 * x + 2 * p2 * y;
    const double jyy = radial + 2 * y * y * dradial + 6 * p1 * y + 2 * p2 * x;
    Eigen::Matrix2d j;
    j << jxx, jxy, jxy, jyy;
    return j;
  }
};

// Sensor noise model (ISETCam order). Electrons at clipping scale as FWC * base_iso / iso.
struct SensorNoise {
  double full_well_e = 79546;  // electrons at clipping at base ISO
  double base_iso = 100;
  double read_noise_e = 25;            // at base ISO (estimate for most presets)
  double read_noise_high_iso_e = 1.7;  // at the highest ISO; interpolated in log ISO
  double prnu = 0.007;                 // pixel gain non-uniformity, fraction
  double dsnu_e = 1.0;                 // dark signal non-uniformity, electrons
  double dark_current_e_per_s = 0.1;
  int adc_bits = 14;
  std::string source_note;  // which numbers are measured and which are estimates
};

enum class ImageFormat { kJpeg, kPng16, kTiff16 };

// Which of the DSLR effects a renderer applies (for A/B comparisons).
struct Effects {
  bool depth_of_field = true;
  bool diffraction = true;
  bool motion_blur = true;
  bool distortion = true;
  bool vignetting = true;
  bool noise = true;
};

enum class WhiteBalanceMode { kAuto, kKelvin };

struct Camera {
  std::string body;  // preset name or "custom"
  std::string make;  // EXIF
  std::string model;
  double sensor_width_m = 0.0358;
  double sensor_height_m = 0.0239;
  int width_px = 5472;
  int height_px = 3648;
  double focal_length_m = 0.05;
  // Intrinsics in pixels; pixel centres at +0.5 (COLMAP): the image centre is (w/2, h/2).
  double fx = 0, fy = 0, cx = 0, cy = 0;
  Distortion distortion;
  double vignetting = 0;  // fraction of light lost in the image corners (0..1)
  double aperture_f_number = 8;
  double shutter_s = 1.0 / 125;
  double iso = 100;
  WhiteBalanceMode white_balance = WhiteBalanceMode::kAuto;
  double white_balance_k = 5600;
  SensorNoise noise;
  Effects effects;
  ImageFormat format = ImageFormat::kJpeg;
  int jpeg_quality = 95;
  double circle_of_confusion_m = 0.03e-3;  // acceptable blur for DOF advice (diagonal / 1500)
  SourceLoc loc;
  // Where the exposure settings and the lens's distortion were written, for capture advice at
  // the responsible line.
  SourceLoc aperture_loc, shutter_loc, iso_loc, focus_loc, distortion_loc;
};

// Thresholds of the coverage analysis: when a view of a face is usable by SfM.
struct CoverageSettings {
  double min_pixels_per_mm2 = 1.0;                 // image resolution on the surface
  double max_view_angle_rad = 1.3089969389957472;  // 75 deg between normal and view ray
  double max_blur_px = 0;  // circle of confusion still "in focus", pixels; 0: diagonal/1500
  double min_triangulation_angle_rad = 0.08726646259971647;  // 5 deg between two usable views
  double min_signal = 0.02;      // normalised signal below: too dark (noise)
  double max_signal = 0.98;      // above: clipped
  double min_overlap = 0.6;      // of consecutive shots' seen surface
  double min_frame_fill = 0.05;  // object's share of the image area
  SourceLoc loc;
};

enum class ShotKind { kTurntable, kOrbit, kPose };

struct Shot {
  int index = 0;
  std::string name;  // shot_000
  ShotKind kind = ShotKind::kPose;
  Mat4 world_from_camera = Mat4::Identity();
  double turntable_angle_rad = 0;       // object rotation about world +Z at mid-exposure
  double turntable_velocity_rad_s = 0;  // rotation speed during the exposure
  double focus_distance_m = 1;          // along the optical axis
  // The camera pose relative to the object (object rotated back to angle 0): what SfM recovers.
  Mat4 object_from_camera = Mat4::Identity();
  SourceLoc loc;
};

struct Scene {
  int language_version = 1;
  std::string name;
  std::string source_file;
  Object object;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  Studio studio;
  Camera camera;
  std::vector<Shot> shots;
  CoverageSettings coverage;
};

// world_from_object for a turntable angle.
Mat4 world_from_object(const Scene& scene, double turntable_angle_rad);

// The object's mesh positions in the object frame (through object_from_mesh, in double, stored
// as float): the ground truth eval measures against.
std::vector<Eigen::Vector3f> object_frame_positions(const Object& object);

}  // namespace rigc::ir
