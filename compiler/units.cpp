#include "compiler/units.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

namespace rigc {
namespace {

struct UnitDef {
  const char* symbol;
  QuantityKind kind;
  double to_si;
};

const std::vector<UnitDef>& unit_table() {
  static const std::vector<UnitDef> table = {
      {"m", QuantityKind::kLength, 1.0},
      {"cm", QuantityKind::kLength, 0.01},
      {"mm", QuantityKind::kLength, 0.001},
      {"um", QuantityKind::kLength, 1e-6},  // a pixel's pitch
      {"µm", QuantityKind::kLength, 1e-6},
      {"in", QuantityKind::kLength, 0.0254},
      {"deg", QuantityKind::kAngle, kDegree},
      {"°", QuantityKind::kAngle, kDegree},
      {"rad", QuantityKind::kAngle, 1.0},
      {"s", QuantityKind::kTime, 1.0},
      {"ms", QuantityKind::kTime, 0.001},
      {"K", QuantityKind::kTemperature, 1.0},
      {"W", QuantityKind::kPower, 1.0},
      {"kW", QuantityKind::kPower, 1000.0},
      {"lx", QuantityKind::kIlluminance, 1.0},
      {"lux", QuantityKind::kIlluminance, 1.0},
      {"deg/s", QuantityKind::kAngularVelocity, kDegree},
      {"rad/s", QuantityKind::kAngularVelocity, 1.0},
      {"rpm", QuantityKind::kAngularVelocity, 2.0 * std::numbers::pi / 60.0},
  };
  return table;
}

// Splits "12.5cm" into 12.5 and "cm"; returns false if there is no leading decimal number.
// std::from_chars, unlike std::stod, reads no hexadecimal: "0x10cm" would be 0x10c metres.
bool split_number(const std::string& text, double* number, std::string* unit) {
  const char* first = text.data() + std::min(text.find_first_not_of(" \t"), text.size());
  const char* last = text.data() + text.size();
  if (first != last && *first == '+' && last - first > 1 && first[1] != '-') ++first;
  const auto [end, error] = std::from_chars(first, last, *number, std::chars_format::general);
  // from_chars accepts "inf" and "nan": a quantity must be a finite number.
  if (error != std::errc() || !std::isfinite(*number)) return false;
  std::string rest(end, last);
  size_t start = rest.find_first_not_of(" \t");
  *unit = start == std::string::npos ? "" : rest.substr(start);
  return true;
}

std::string trim(const std::string& text) {
  size_t first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  size_t last = text.find_last_not_of(" \t");
  return text.substr(first, last - first + 1);
}

}  // namespace

std::string kind_description(QuantityKind kind) {
  switch (kind) {
    case QuantityKind::kNumber:
      return "a number";
    case QuantityKind::kLength:
      return "a length";
    case QuantityKind::kAngle:
      return "an angle";
    case QuantityKind::kTime:
      return "a time";
    case QuantityKind::kFNumber:
      return "an f-number";
    case QuantityKind::kTemperature:
      return "a colour temperature";
    case QuantityKind::kPower:
      return "a power";
    case QuantityKind::kIlluminance:
      return "an illuminance";
    case QuantityKind::kAngularVelocity:
      return "an angular velocity";
  }
  return "a quantity";
}

std::string kind_units(QuantityKind kind) {
  switch (kind) {
    case QuantityKind::kNumber:
      return "no unit";
    case QuantityKind::kLength:
      return "m, cm, mm, in";
    case QuantityKind::kAngle:
      return "deg, rad";
    case QuantityKind::kTime:
      return "s, ms, or a fraction such as 1/125";
    case QuantityKind::kFNumber:
      return "f/N, e.g. f/8";
    case QuantityKind::kTemperature:
      return "K";
    case QuantityKind::kPower:
      return "W, kW";
    case QuantityKind::kIlluminance:
      return "lx";
    case QuantityKind::kAngularVelocity:
      return "deg/s, rad/s, rpm";
  }
  return "";
}

std::string format_quantity(double v, QuantityKind kind) {
  switch (kind) {
    case QuantityKind::kLength:
      if (v != 0 && std::abs(v) < 1e-4) return fmt::format("{:g}um", v * 1e6);
      if (std::abs(v) < 0.01) return fmt::format("{:g}mm", v * 1000);
      if (std::abs(v) < 1) return fmt::format("{:g}cm", v * 100);
      return fmt::format("{:g}m", v);
    case QuantityKind::kAngle:
      return fmt::format("{:g}deg", v / kDegree);
    case QuantityKind::kTime:
      if (v > 0 && v < 0.5) return fmt::format("1/{:g}s", std::round(1.0 / v));
      return fmt::format("{:g}s", v);
    case QuantityKind::kFNumber:
      return fmt::format("f/{:g}", v);
    case QuantityKind::kTemperature:
      return fmt::format("{:g}K", v);
    case QuantityKind::kPower:
      return fmt::format("{:g}W", v);
    case QuantityKind::kIlluminance:
      return fmt::format("{:g}lx", v);
    case QuantityKind::kAngularVelocity:
      return fmt::format("{:g}deg/s", v / kDegree);
    case QuantityKind::kNumber:
      return fmt::format("{:g}", v);
  }
  return fmt::format("{:g}", v);
}

QuantityParse parse_quantity(const std::string& raw, QuantityKind kind) {
  const std::string text = trim(raw);
  QuantityParse result;
  auto fail = [&](std::string why) {
    result.error = std::move(why);
    return result;
  };
  const std::string expected =
      fmt::format("expected {} ({}), got '{}'", kind_description(kind), kind_units(kind), text);

  if (kind == QuantityKind::kFNumber) {
    std::string digits = text;
    if (digits.rfind("f/", 0) == 0 || digits.rfind("F/", 0) == 0) {
      digits = digits.substr(2);
    } else if (!digits.empty() && (digits[0] == 'f' || digits[0] == 'F')) {
      digits = digits.substr(1);
    }
    double number = 0;
    std::string unit;
    if (!split_number(digits, &number, &unit) || !unit.empty()) return fail(expected);
    result.value = number;
    return result;
  }

  // Shutter speeds as fractions of a second: 1/125, 1/125s.
  if (kind == QuantityKind::kTime) {
    size_t slash = text.find('/');
    if (slash != std::string::npos) {
      double numerator = 0, denominator = 0;
      std::string unit_n, unit_d;
      if (!split_number(text.substr(0, slash), &numerator, &unit_n) || !unit_n.empty() ||
          !split_number(text.substr(slash + 1), &denominator, &unit_d) ||
          (!unit_d.empty() && unit_d != "s")) {
        return fail(expected);
      }
      if (denominator == 0) return fail(fmt::format("division by zero in '{}'", text));
      if (!std::isfinite(numerator / denominator)) return fail(expected);
      result.value = numerator / denominator;
      return result;
    }
  }

  double number = 0;
  std::string unit;
  if (!split_number(text, &number, &unit)) return fail(expected);
  if (unit.empty()) {
    result.value = kind == QuantityKind::kAngle || kind == QuantityKind::kAngularVelocity
                       ? number * kDegree
                       : number;
    return result;
  }
  for (const auto& def : unit_table()) {
    if (unit != def.symbol) continue;
    if (def.kind != kind) {
      return fail(fmt::format("'{}' is {}, expected {} ({})", text, kind_description(def.kind),
                              kind_description(kind), kind_units(kind)));
    }
    if (!std::isfinite(number * def.to_si)) return fail(expected);
    result.value = number * def.to_si;
    return result;
  }
  return fail(fmt::format("unknown unit '{}' in '{}'; expected {} ({})", unit, text,
                          kind_description(kind), kind_units(kind)));
}

}  // namespace rigc
