// Quantities with units, as written in scene files: `80cm`, `20deg`, `1/125`, `f/8`, `5600K`.
// Everything is converted to SI (meters, radians, seconds, kelvin, watts, lux, rad/s).
#pragma once

#include <numbers>
#include <optional>
#include <string>

namespace rigc {

// One degree, in radians.
inline constexpr double kDegree = std::numbers::pi / 180.0;

enum class QuantityKind {
  kNumber,           // dimensionless
  kLength,           // m, cm, mm, in; bare number: m
  kAngle,            // deg, rad; bare number: deg
  kTime,             // s, ms, 1/125; bare number: s
  kFNumber,          // f/8, F8; bare number: the f-number
  kTemperature,      // K; bare number: K
  kPower,            // W, kW; bare number: W
  kIlluminance,      // lx, lux; bare number: lx
  kAngularVelocity,  // deg/s, rad/s, rpm; bare number: deg/s
};

// "a length", "an angle", ... for messages.
std::string kind_description(QuantityKind kind);
// The units accepted for a kind, for messages: "m, cm, mm, in".
std::string kind_units(QuantityKind kind);
// How an SI value is best shown to the user: 0.8 m -> "80cm", 0.008 s -> "1/125s".
std::string format_quantity(double si_value, QuantityKind kind);

struct QuantityParse {
  std::optional<double> value;  // SI, set on success
  std::string error;            // set on failure: why, for the user
};

QuantityParse parse_quantity(const std::string& text, QuantityKind kind);

}  // namespace rigc
