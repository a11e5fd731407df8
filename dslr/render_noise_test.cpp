#include "dslr/render_noise.h"

#include <gtest/gtest.h>

#include "dslr/exposure.h"
#include "dslr/sensor.h"

namespace rigc::dslr {
namespace {

ir::Camera camera_at_iso(double iso) {
  ir::Camera camera;
  camera.aperture_f_number = 8;
  camera.shutter_s = 1.0 / 125;
  camera.iso = iso;
  return camera;
}

// A frame of `value` cd/m² in every channel, every pixel on the object.
LinearFrame flat_frame(int width, int height, float value) {
  LinearFrame frame;
  frame.width = width;
  frame.height = height;
  frame.rgb.assign(3 * static_cast<std::size_t>(width) * height, value);
  frame.mask.assign(static_cast<std::size_t>(width) * height, 255);
  return frame;
}

TEST(SensorNoiseVariance, IsShotNoisePlusReadNoiseInRadianceUnits) {
  const ir::Camera camera = camera_at_iso(400);
  const double per_unit = exposure_scale(camera) * electrons_at_clipping(camera.noise, 400);
  const double read = read_noise_electrons(camera.noise, 400);
  const double radiance = 50;
  EXPECT_NEAR(sensor_noise_variance(camera, radiance),
              (radiance * per_unit + read * read) / (per_unit * per_unit), 1e-12);
}

TEST(RenderNoise, IsHalfTheSquaredDifferenceOverTheSensorsVariance) {
  const ir::Camera camera = camera_at_iso(200);
  LinearFrame a = flat_frame(4, 2, 40), b = flat_frame(4, 2, 40);
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    a.rgb[i] += (i % 2 ? 0.5f : -0.5f);
    b.rgb[i] -= (i % 2 ? 0.5f : -0.5f);
  }
  // Off the object in one frame: left out, however different.
  a.mask[0] = 0;
  a.rgb[0] = 1000;
  const RenderNoise noise = measure_render_noise(camera, a, b);
  EXPECT_EQ(noise.pixels, 7);
  EXPECT_NEAR(noise.renderer_variance, 0.5, 1e-9);  // (1)² / 2
  EXPECT_NEAR(noise.sensor_variance, sensor_noise_variance(camera, 40), 1e-9);
  EXPECT_NEAR(noise.ratio(), 0.5 / sensor_noise_variance(camera, 40), 1e-9);
}

TEST(RenderNoise, FramesOfDifferentSizesShareNoPixel) {
  const ir::Camera camera = camera_at_iso(200);
  const RenderNoise noise =
      measure_render_noise(camera, flat_frame(4, 2, 40), flat_frame(2, 4, 40));
  EXPECT_EQ(noise.pixels, 0);
  EXPECT_EQ(noise.ratio(), 0);
}

}  // namespace
}  // namespace rigc::dslr
