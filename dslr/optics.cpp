#include "dslr/optics.h"

#include <cmath>

namespace rigc::dslr {

double coc_diameter_m(double focal_length_m, double f_number, double focus_m, double depth_m) {
  const double f = focal_length_m;
  if (!(focus_m > f) || !(depth_m > 0)) return 0;
  const double aperture = f / f_number;
  const double relative = std::isinf(depth_m) ? 1.0 : std::abs(depth_m - focus_m) / depth_m;
  return aperture * f * relative / (focus_m - f);
}

double coc_in_image_m(double focal_length_m, double f_number, double focus_m, double depth_m) {
  if (!(focus_m > focal_length_m)) return 0;
  return coc_diameter_m(focal_length_m, f_number, focus_m, depth_m) * (focus_m - focal_length_m) /
         focus_m;
}

double hyperfocal_m(double focal_length_m, double f_number, double coc_m) {
  return focal_length_m * focal_length_m / (f_number * coc_m) + focal_length_m;
}

}  // namespace rigc::dslr
