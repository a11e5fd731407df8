// Optical blur: the thin-lens formulas, and the depth of field and diffraction that apply them to
// the undistorted canvas (docs/camera-model.md).
#pragma once

#include "dslr/depth_of_field.h"
#include "dslr/diffraction.h"

namespace rigc::dslr {

// Thin lens: diameter on the sensor (m) of the circle of confusion of a point at depth_m when
// focused at focus_m: c = (f/N)·f·|S2 - S1| / (S2·(S1 - f)). depth_m = +inf gives the limit
// (f/N)·f/(S1 - f). Zero when the focus is inside the focal length (not a real focus).
double coc_diameter_m(double focal_length_m, double f_number, double focus_m, double depth_m);

// The same circle in the picture the renderers make, a pinhole of focal length f (no focus
// breathing): the sensor's circle times f/v = (S1 - f)/S1, c' = (f/N)·f·|S2 - S1| / (S2·S1). A real
// lens focused at S1 images at v = f·S1/(S1 - f), a picture v/f larger with the blur c; Cycles'
// lens renders c'. Zero where coc_diameter_m is.
double coc_in_image_m(double focal_length_m, double f_number, double focus_m, double depth_m);

// Hyperfocal distance H = f²/(N·c0) + f.
double hyperfocal_m(double focal_length_m, double f_number, double coc_m);

}  // namespace rigc::dslr
