// Diffraction: the Airy disc as a Gaussian blur of the undistorted canvas (docs/camera-model.md).
#pragma once

#include <vector>

#include "dslr/frame.h"
#include "ir/ir.h"

namespace rigc::dslr {

// Gaussian stand-in for the Airy disc: σ ≈ 0.42·λ·N (m on the sensor).
double diffraction_sigma_m(double f_number, double wavelength_m = 550e-9);
// The taps the diffraction Gaussian of `sigma_px` keeps on each side: out to 3σ, but not those
// below a thousandth of the centre tap's weight (at f/13 on a 6D, σ = 0.46 px: the taps at ±2 px
// weigh 8e-5 of it, and would make a 5-tap pass of a 3-tap one). At least one (σ from 0.2 px,
// where diffraction starts, to 0.27 px keeps lighter ±1 taps).
int diffraction_radius_px(double sigma_px);

// Diffraction as a separable Gaussian of σ = 0.42·λ·N (λ = 550 nm) in canvas pixels, skipped
// below 0.2 px. Applied after the disc blur it adds variances as docs/camera-model.md combines
// them (σ² = σ_diffraction² + (c/4)²). Returns the σ used (0 when skipped). Written over `rgb`.
double apply_diffraction(const ir::Camera& camera, const Intrinsics& canvas,
                         std::vector<float>& rgb);

}  // namespace rigc::dslr
