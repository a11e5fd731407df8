// The language's limits: the range of every bounded value a scene can hold, in one table.
// The checker enforces them, the capture advice keeps its suggestions inside them, and
// schema/rigc.schema.json states them too (compiler/limits_test.cpp holds the schema to this
// table). Each entry names its value by its path in the scene and in the schema: the keys from the
// top, lists left out ("shots.orbit.rings.count").
#pragma once

#include <array>
#include <cstddef>
#include <string_view>

#include "compiler/units.h"

namespace rigc::limits {

// A quantity within `min`..`max`, in SI units (see `kind`); `min` itself is outside when
// `min_exclusive`.
struct Quantity {
  std::string_view path;
  QuantityKind kind;
  double min;
  double max;
  bool min_exclusive = false;
};

// A whole number within `min`..`max`.
struct Integer {
  std::string_view path;
  int min;
  int max;
};

// At most `max` bytes of text, or items of a list.
struct Count {
  enum Of { kBytes, kItems };
  std::string_view path;
  Of of;
  std::size_t max;
};

// Shared shapes of range.
constexpr Quantity unit_interval(std::string_view path) {
  return {path, QuantityKind::kNumber, 0, 1};
}
constexpr Quantity full_turn(std::string_view path) {  // a turn either way
  return {path, QuantityKind::kAngle, -360 * kDegree, 360 * kDegree};
}
constexpr Quantity distance(std::string_view path) {
  return {path, QuantityKind::kLength, 0.01, 1000};
}
// A coordinate of a point: within a kilometre of the turntable's centre, as distances are.
constexpr Quantity position(std::string_view path) {
  return {path, QuantityKind::kLength, -1000, 1000};
}

inline constexpr Integer kLanguageVersion{"rigc", 1, 1};
// The scene's name is a folder of the default run path (out/<name>/<backend>).
inline constexpr Count kSceneName{"name", Count::kBytes, 100};

namespace object {
inline constexpr Integer kPrimitiveDetail{"object.primitive.detail", 1, 9};
inline constexpr Integer kPrimitiveSeed{"object.primitive.seed", 0, 1 << 30};
inline constexpr Quantity kFitHeight{"object.fit.height", QuantityKind::kLength, 0.001, 100};
inline constexpr Quantity kFitWidth{"object.fit.width", QuantityKind::kLength, 0.001, 100};
inline constexpr Quantity kFitSize{"object.fit.size", QuantityKind::kLength, 0.001, 100};
inline constexpr Quantity kScale{"object.scale", QuantityKind::kNumber, 0, 1e6, true};
inline constexpr Quantity kPatternScale{"object.surface.scale", QuantityKind::kLength, 0.0001, 1};
inline constexpr Quantity kPatternContrast = unit_interval("object.surface.contrast");
inline constexpr Integer kPatternSeed{"object.surface.seed", 0, 1 << 30};
inline constexpr Quantity kColor = unit_interval("object.surface.color");
inline constexpr Quantity kRoughness = unit_interval("object.surface.roughness");
inline constexpr Quantity kMetallic = unit_interval("object.surface.metallic");
inline constexpr Quantity kRotate = full_turn("object.rotate");
inline constexpr Quantity kTranslate = position("object.translate");
}  // namespace object

namespace studio {
inline constexpr Quantity kTurntableDiameter{"studio.turntable.diameter", QuantityKind::kLength,
                                             0.01, 10};
inline constexpr Quantity kTurntableHeight{"studio.turntable.height", QuantityKind::kLength, 0, 5};
inline constexpr Quantity kTurntableThickness{"studio.turntable.thickness", QuantityKind::kLength,
                                              0.001, 1};
inline constexpr Quantity kTurntableColor = unit_interval("studio.turntable.color");
inline constexpr Quantity kGreenScreenColor = unit_interval("studio.backdrop.green_screen.color");
inline constexpr Quantity kBackdropColor = unit_interval("studio.backdrop.color");
inline constexpr Quantity kBackdropDistance{"studio.backdrop.distance", QuantityKind::kLength, 0.05,
                                            100};
inline constexpr Quantity kBackdropWidth{"studio.backdrop.width", QuantityKind::kLength, 0.1, 100};
inline constexpr Quantity kBackdropHeight{"studio.backdrop.height", QuantityKind::kLength, 0.1,
                                          100};
// Each light has a shadow map, tens of MB at full size.
inline constexpr Count kLights{"studio.lights", Count::kItems, 32};
inline constexpr Quantity kLightPower{"studio.lights.power", QuantityKind::kPower, 0, 1e6, true};
inline constexpr Quantity kLightIlluminance{"studio.lights.illuminance", QuantityKind::kIlluminance,
                                            0, 200000, true};
inline constexpr Quantity kLightTemperature{"studio.lights.temperature", QuantityKind::kTemperature,
                                            1000, 40000};
inline constexpr Quantity kAreaLightSize{"studio.lights.size", QuantityKind::kLength, 0.001, 20};
inline constexpr Quantity kSpotAngle{"studio.lights.angle", QuantityKind::kAngle, 1 * kDegree,
                                     180 * kDegree};
inline constexpr Quantity kSpotBlend = unit_interval("studio.lights.blend");
inline constexpr Quantity kAmbient{"studio.ambient", QuantityKind::kIlluminance, 0, 200000};
inline constexpr Quantity kFloorColor = unit_interval("studio.floor.color");
inline constexpr Quantity kLightPosition = position("studio.lights.position");
inline constexpr Quantity kLightLookAt = position("studio.lights.look_at");
}  // namespace studio

namespace camera {
inline constexpr Quantity kSensorWidth{"camera.sensor.width", QuantityKind::kLength, 0.001, 0.2};
inline constexpr Quantity kSensorHeight{"camera.sensor.height", QuantityKind::kLength, 0.001, 0.2};
inline constexpr Integer kSensorPixels{"camera.sensor.pixels", 16, 20000};
// A camera given by its intrinsics: an image of the sizes a sensor may have, focal lengths in
// pixels, and the pitch that gives them a size in metres (the focal length, the sensor).
inline constexpr Integer kIntrinsicsWidth{"camera.intrinsics.width", kSensorPixels.min,
                                          kSensorPixels.max};
inline constexpr Integer kIntrinsicsHeight{"camera.intrinsics.height", kSensorPixels.min,
                                           kSensorPixels.max};
inline constexpr Quantity kIntrinsicsFx{"camera.intrinsics.fx", QuantityKind::kNumber, 0, 1e6,
                                        true};
inline constexpr Quantity kIntrinsicsFy{"camera.intrinsics.fy", QuantityKind::kNumber, 0, 1e6,
                                        true};
inline constexpr Quantity kPixelPitch{"camera.intrinsics.pixel_pitch", QuantityKind::kLength,
                                      0.5e-6, 50e-6};
// EXIF text: a JPEG marker holds under 64 KB; real cameras write a few dozen characters.
inline constexpr Count kMake{"camera.make", Count::kBytes, 255};
inline constexpr Count kModel{"camera.model", Count::kBytes, 255};
inline constexpr Quantity kFocalLength{"camera.lens.focal_length", QuantityKind::kLength, 0.004,
                                       1.2};
inline constexpr Quantity kDistortionK1{"camera.lens.distortion.k1", QuantityKind::kNumber, -1, 1};
inline constexpr Quantity kDistortionK2{"camera.lens.distortion.k2", QuantityKind::kNumber, -1, 1};
inline constexpr Quantity kDistortionK3{"camera.lens.distortion.k3", QuantityKind::kNumber, -1, 1};
inline constexpr Quantity kDistortionP1{"camera.lens.distortion.p1", QuantityKind::kNumber, -1, 1};
inline constexpr Quantity kDistortionP2{"camera.lens.distortion.p2", QuantityKind::kNumber, -1, 1};
inline constexpr Quantity kVignetting{"camera.lens.vignetting", QuantityKind::kNumber, 0, 0.95};
// The ISO 12232 stops that the seed paper's DSLR model offers.
inline constexpr Quantity kAperture{"camera.exposure.aperture", QuantityKind::kFNumber, 1.2, 64};
inline constexpr Quantity kShutter{"camera.exposure.shutter", QuantityKind::kTime, 1.0 / 8000, 30};
inline constexpr Quantity kIso{"camera.exposure.iso", QuantityKind::kNumber, 100, 51200};
inline constexpr Quantity kFocusDistance = distance("camera.focus");
inline constexpr Quantity kWhiteBalance{"camera.white_balance", QuantityKind::kTemperature, 2000,
                                        12000};
inline constexpr Integer kJpegQuality{"camera.output.quality", 1, 100};
}  // namespace camera

namespace shots {
inline constexpr Integer kTurntableSteps{"shots.turntable.steps", 1, 3600};
inline constexpr Quantity kTurntableStep = full_turn("shots.turntable.step");
inline constexpr Quantity kTurntableStart = full_turn("shots.turntable.start");
inline constexpr Quantity kTurntableSpeed{"shots.turntable.speed", QuantityKind::kAngularVelocity,
                                          -100, 100};
inline constexpr Quantity kTurntableCameraDistance = distance("shots.turntable.camera.distance");
inline constexpr Quantity kTurntableCameraHeight{"shots.turntable.camera.height",
                                                 QuantityKind::kLength, -100, 100};
inline constexpr Quantity kTurntableCameraAzimuth = full_turn("shots.turntable.camera.azimuth");
inline constexpr Quantity kOrbitDistance = distance("shots.orbit.distance");
inline constexpr Quantity kRingElevation{"shots.orbit.rings.elevation", QuantityKind::kAngle,
                                         -90 * kDegree, 90 * kDegree};
inline constexpr Integer kRingCount{"shots.orbit.rings.count", 1, 3600};
inline constexpr Quantity kRingStart = full_turn("shots.orbit.rings.start");
inline constexpr Quantity kPoseTurntable = full_turn("shots.pose.turntable");
inline constexpr Quantity kTurntableCameraAim = position("shots.turntable.camera.aim");
inline constexpr Quantity kOrbitAim = position("shots.orbit.aim");
inline constexpr Quantity kPosePosition = position("shots.pose.position");
inline constexpr Quantity kPoseLookAt = position("shots.pose.look_at");
}  // namespace shots

namespace coverage {
inline constexpr Quantity kMinPixelsPerMm2{"coverage.min_pixels_per_mm2", QuantityKind::kNumber, 0,
                                           1e6};
inline constexpr Quantity kMaxViewAngle{"coverage.max_view_angle", QuantityKind::kAngle,
                                        1 * kDegree, 90 * kDegree};
inline constexpr Quantity kMaxBlur{"coverage.max_blur", QuantityKind::kNumber, 0.1, 1000};
inline constexpr Quantity kMinTriangulationAngle{"coverage.min_triangulation_angle",
                                                 QuantityKind::kAngle, 0, 90 * kDegree};
inline constexpr Quantity kMinSignal = unit_interval("coverage.min_signal");
inline constexpr Quantity kMaxSignal = unit_interval("coverage.max_signal");
inline constexpr Quantity kMinOverlap = unit_interval("coverage.min_overlap");
inline constexpr Quantity kMinFrameFill = unit_interval("coverage.min_frame_fill");
}  // namespace coverage

// Every entry above, for the schema's test.
inline constexpr std::array kQuantities = {
    object::kFitHeight,
    object::kFitWidth,
    object::kFitSize,
    object::kScale,
    object::kPatternScale,
    object::kPatternContrast,
    object::kColor,
    object::kRoughness,
    object::kMetallic,
    object::kRotate,
    object::kTranslate,
    studio::kTurntableDiameter,
    studio::kTurntableHeight,
    studio::kTurntableThickness,
    studio::kTurntableColor,
    studio::kGreenScreenColor,
    studio::kBackdropColor,
    studio::kBackdropDistance,
    studio::kBackdropWidth,
    studio::kBackdropHeight,
    studio::kLightPower,
    studio::kLightIlluminance,
    studio::kLightTemperature,
    studio::kAreaLightSize,
    studio::kSpotAngle,
    studio::kSpotBlend,
    studio::kAmbient,
    studio::kFloorColor,
    studio::kLightPosition,
    studio::kLightLookAt,
    camera::kSensorWidth,
    camera::kSensorHeight,
    camera::kIntrinsicsFx,
    camera::kIntrinsicsFy,
    camera::kPixelPitch,
    camera::kFocalLength,
    camera::kDistortionK1,
    camera::kDistortionK2,
    camera::kDistortionK3,
    camera::kDistortionP1,
    camera::kDistortionP2,
    camera::kVignetting,
    camera::kAperture,
    camera::kShutter,
    camera::kIso,
    camera::kFocusDistance,
    camera::kWhiteBalance,
    shots::kTurntableStep,
    shots::kTurntableStart,
    shots::kTurntableSpeed,
    shots::kTurntableCameraDistance,
    shots::kTurntableCameraHeight,
    shots::kTurntableCameraAzimuth,
    shots::kOrbitDistance,
    shots::kRingElevation,
    shots::kRingStart,
    shots::kPoseTurntable,
    shots::kTurntableCameraAim,
    shots::kOrbitAim,
    shots::kPosePosition,
    shots::kPoseLookAt,
    coverage::kMinPixelsPerMm2,
    coverage::kMaxViewAngle,
    coverage::kMaxBlur,
    coverage::kMinTriangulationAngle,
    coverage::kMinSignal,
    coverage::kMaxSignal,
    coverage::kMinOverlap,
    coverage::kMinFrameFill,
};
inline constexpr std::array kIntegers = {
    kLanguageVersion,          object::kPrimitiveDetail, object::kPrimitiveSeed,
    object::kPatternSeed,      camera::kSensorPixels,    camera::kIntrinsicsWidth,
    camera::kIntrinsicsHeight, camera::kJpegQuality,     shots::kTurntableSteps,
    shots::kRingCount,
};
inline constexpr std::array kCounts = {kSceneName, studio::kLights, camera::kMake, camera::kModel};

// Limits on the scene as a whole, which no schema can state.
// Far more photos than a capture takes (and than COLMAP matches in a day).
inline constexpr std::size_t kMostShots = 5000;
// The object after fit, scale and translate: its largest extent, and how far it may reach from
// the turntable's centre.
inline constexpr double kObjectSmallestM = 1e-3;
inline constexpr double kObjectLargestM = 100;
inline constexpr double kObjectReachM = 1000;
// A scene is a few kilobytes of text; meshes and textures are files of their own.
inline constexpr std::size_t kMostSceneFileBytes = 16 << 20;

}  // namespace rigc::limits
