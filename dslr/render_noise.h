// How much noise a renderer adds of its own, against the simulated sensor's: what a converged
// reference (`--samples auto`) is held to (docs/fidelity.md, "Converged references").
#pragma once

#include "dslr/frame.h"
#include "ir/ir.h"

namespace rigc::dslr {

// The sensor's temporal noise variance at a pixel of `radiance` cd/m² (one channel), in
// (cd/m²)²: photon shot noise and read noise at the camera's ISO, before the ADC.
double sensor_noise_variance(const ir::Camera& camera, double radiance);

// Two renders of one shot that differ only in the renderer's seed, over the pixels both masks
// hold: the renderer's variance per channel, mean (a - b)² / 2, against the sensor's at their mean
// radiance. `pixels` is 0 (and the ratio 0) when the frames differ in size or share no pixel.
struct RenderNoise {
  long pixels = 0;
  double renderer_variance = 0;  // (cd/m²)², mean over pixels and channels
  double sensor_variance = 0;    // (cd/m²)², the same mean
  double ratio() const { return sensor_variance > 0 ? renderer_variance / sensor_variance : 0; }
};
RenderNoise measure_render_noise(const ir::Camera& camera, const LinearFrame& a,
                                 const LinearFrame& b);

}  // namespace rigc::dslr
