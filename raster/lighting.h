// Internal to the rasterizer: the lights' radiometry (the frame's lights in float, one light's
// illuminance at a point) and the GGX specular lobe. Inline: the shading loop calls them per
// light for about a million points a frame.
#pragma once

#include <algorithm>
#include <cmath>

#include "ir/ir.h"
#include "raster/raster_common.h"

namespace rigc::raster {

inline constexpr float kLumensPerWatt = static_cast<float>(ir::kLumensPerWatt);

// A light with its constants in float, worked out once per frame rather than per pixel.
struct FrameLight {
  ir::LightType type = ir::LightType::kPoint;
  Vector3f position = Vector3f::Zero();
  Vector3f direction = Vector3f::UnitZ();  // unit
  // Directional: colour x illuminance (lux). Area: colour x on-axis intensity (cd). Point and
  // spot: colour x intensity (cd).
  Vector3f scaled_color = Vector3f::Zero();
  float spot_outer_cos = -1, spot_inner_cos = -1;
  // Area: the squared radius of the disc of the panel's area (its size, for the highlight).
  float disc_radius2 = 0;

  explicit FrameLight(const ir::Light& light, const Vector3f& color)
      : type(light.type),
        position(light.position.cast<float>()),
        direction(light.direction.cast<float>().normalized()) {
    const float watts = static_cast<float>(light.power_w);
    switch (type) {
      case ir::LightType::kDirectional:
        scaled_color = color * static_cast<float>(light.illuminance_lx);
        break;
      case ir::LightType::kArea:
        // A one-sided Lambertian emitter of power P has intensity P/π along its normal.
        scaled_color = color * (kLumensPerWatt * watts / kPi);
        disc_radius2 = static_cast<float>(light.size_m.x() * light.size_m.y()) / kPi;
        break;
      case ir::LightType::kPoint:
      case ir::LightType::kSpot: {
        scaled_color = color * (kLumensPerWatt * watts / (4 * kPi));
        const float half = static_cast<float>(light.spot_angle_rad / 2);
        spot_outer_cos = std::cos(half);
        spot_inner_cos = std::cos(half * (1 - static_cast<float>(light.spot_blend)));
        break;
      }
    }
  }
};

// Radiometry of one light at a point: the colour-weighted illuminance (lux) arriving along
// `to_light`.
struct LightSample {
  Vector3f to_light;
  Vector3f illuminance;  // per channel, lux
  // The square of half the light's angular radius from the point: how far the half vector
  // spreads over the light, added to the highlight's α² (ggx_specular).
  float half_vector_spread2 = 0;
};

// Always inlined: left to itself GCC keeps it a call from the lighting loop, which runs about a
// million times a frame.
__attribute__((always_inline)) inline bool sample_light(const FrameLight& light, const Vector3f& p,
                                                        LightSample* out) {
  if (light.type == ir::LightType::kDirectional) {
    out->to_light = -light.direction;
    out->illuminance = light.scaled_color;
    out->half_vector_spread2 = 0;
    return true;
  }
  const Vector3f d = light.position - p;
  const float dist2 = std::max(d.squaredNorm(), 1e-6f);
  out->to_light = d / std::sqrt(dist2);
  const float size2 = light.disc_radius2 / dist2;  // (R/D)²: 0 but for area lights
  float falloff = 1 / dist2;
  if (light.type == ir::LightType::kArea) {
    // The panel's cosine, and its size: a Lambertian disc of radius R seen on axis from D gives
    // 1 / (1 + R²/D²) of what its centre alone would.
    falloff *= std::max(0.0f, -light.direction.dot(out->to_light)) / (1 + size2);
  } else if (light.type == ir::LightType::kSpot) {
    const float cos_axis = light.direction.dot(-out->to_light);
    const float t = std::clamp((cos_axis - light.spot_outer_cos) /
                                   std::max(light.spot_inner_cos - light.spot_outer_cos, 1e-4f),
                               0.0f, 1.0f);
    falloff *= t * t * (3 - 2 * t);
  }
  out->illuminance = light.scaled_color * falloff;
  out->half_vector_spread2 = size2 / 4;
  return falloff > 0;
}

// GGX microfacet specular (Smith-Schlick visibility), times π so that it sits beside albedo/π·π.
// A light of some size widens the lobe it is seen in: `spread2` is added to α² (a convolution of
// two narrow lobes adds their variances), which lowers a glossy highlight's peak as integrating
// over the light does.
// (Seven parameters: one light's and pixel's dot products, inlined into the shading loop.)
inline float ggx_specular(float n_dot_l, float n_dot_v, float n_dot_h, float v_dot_h,
                          float roughness, float f0, float spread2) {
  const float alpha = std::max(roughness * roughness, 0.002f);
  const float a2 = alpha * alpha + spread2;
  const float denom = n_dot_h * n_dot_h * (a2 - 1) + 1;
  const float d = a2 / (kPi * denom * denom);
  const float k = alpha / 2;
  const float vis = 1 / ((n_dot_l * (1 - k) + k) * (n_dot_v * (1 - k) + k));
  const float fresnel =
      f0 + (1 - f0) * (1 - v_dot_h) * (1 - v_dot_h) * (1 - v_dot_h) * (1 - v_dot_h) * (1 - v_dot_h);
  return d * vis * fresnel / 4;
}

// Burley's diffuse relative to Lambert's, as Blender 3's Principled BSDF has it: darker where
// light or view graze the surface, plus a retro-reflection that grows with roughness and peaks
// with light and view together (1 + l·v = 2 (l·h)²).
inline float burley_diffuse(float n_dot_l, float n_dot_v, float l_dot_v, float roughness) {
  auto schlick = [](float cosine) {
    const float m = std::clamp(1 - cosine, 0.0f, 1.0f);
    return m * m * m * m * m;
  };
  const float fl = schlick(n_dot_l), fv = schlick(n_dot_v);
  const float retro = roughness * (1 + l_dot_v);
  return (1 - 0.5f * fv) * (1 - 0.5f * fl) + retro * (fl + fv + fl * fv * (retro - 1));
}

}  // namespace rigc::raster
