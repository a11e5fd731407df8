#include "dslr/render_noise.h"

#include <algorithm>
#include <cstddef>

#include "dslr/exposure.h"
#include "dslr/sensor.h"

namespace rigc::dslr {

double sensor_noise_variance(const ir::Camera& camera, double radiance) {
  const double electrons_per_unit =
      exposure_scale(camera) * electrons_at_clipping(camera.noise, camera.iso);
  const double read = read_noise_electrons(camera.noise, camera.iso);
  const double electrons = std::max(0.0, radiance) * electrons_per_unit;
  return (electrons + read * read) / (electrons_per_unit * electrons_per_unit);
}

RenderNoise measure_render_noise(const ir::Camera& camera, const LinearFrame& a,
                                 const LinearFrame& b) {
  RenderNoise noise;
  const std::size_t count = static_cast<std::size_t>(a.width) * a.height;
  if (a.width != b.width || a.height != b.height || a.rgb.size() != 3 * count ||
      b.rgb.size() != 3 * count || a.mask.size() != count || b.mask.size() != count) {
    return noise;
  }
  double renderer = 0, sensor = 0;
  for (std::size_t i = 0; i < count; ++i) {
    if (a.mask[i] == 0 || b.mask[i] == 0) continue;
    ++noise.pixels;
    for (std::size_t c = 3 * i; c < 3 * i + 3; ++c) {
      const double difference = static_cast<double>(a.rgb[c]) - b.rgb[c];
      renderer += difference * difference / 2;
      sensor += sensor_noise_variance(camera, (static_cast<double>(a.rgb[c]) + b.rgb[c]) / 2);
    }
  }
  if (noise.pixels == 0) return noise;
  noise.renderer_variance = renderer / (3.0 * noise.pixels);
  noise.sensor_variance = sensor / (3.0 * noise.pixels);
  return noise;
}

}  // namespace rigc::dslr
