// Exposure (APEX, ISO 12232): from scene luminance to the normalised sensor signal.
#pragma once

#include <vector>

#include "ir/ir.h"

namespace rigc::dslr {

// Lens transmission, vignetting and angle factor in H = q·L·t/N² (docs/camera-model.md).
inline constexpr double kExposureQ = 0.65;

// EV100 = log2(N²/t) - log2(ISO/100).
double ev100(double f_number, double shutter_s, double iso);

// v = L·t·ISO·q / (78·N²) = L / (1.2·2^EV100): multiplies cd/m² into the normalised signal
// (1.0 saturates the sensor at this ISO).
double exposure_scale(const ir::Camera& camera);

// Radiance (cd/m²) times exposure_scale. No clipping here (the sensor clips), but negative and
// non-finite radiance (a renderer's stray NaN) becomes 0 so it cannot spread through the blurs.
std::vector<float> expose(const ir::Camera& camera, const std::vector<float>& radiance);
// The same in place.
void expose_in_place(const ir::Camera& camera, std::vector<float>& radiance);

// Length in pixels of the motion blur of a point at R⊥ metres from the turntable axis (the
// component of its motion parallel to the sensor) and depth Z: ω·t·R⊥·f_px / Z.
double motion_blur_length_px(double angular_velocity_rad_s, double shutter_s,
                             double radius_perpendicular_m, double depth_m, double f_px);
double motion_blur_length_px(const ir::Camera& camera, double scale, double angular_velocity_rad_s,
                             double radius_perpendicular_m, double depth_m);

}  // namespace rigc::dslr
