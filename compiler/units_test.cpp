#include "compiler/units.h"

#include <gtest/gtest.h>

#include <numbers>

namespace rigc {
namespace {

double parse_ok(const std::string& text, QuantityKind kind) {
  QuantityParse parsed = parse_quantity(text, kind);
  EXPECT_TRUE(parsed.value.has_value()) << text << ": " << parsed.error;
  return parsed.value.value_or(-1);
}

TEST(Units, LengthsConvertToMeters) {
  EXPECT_DOUBLE_EQ(parse_ok("80cm", QuantityKind::kLength), 0.8);
  EXPECT_DOUBLE_EQ(parse_ok("0.8m", QuantityKind::kLength), 0.8);
  EXPECT_DOUBLE_EQ(parse_ok("50mm", QuantityKind::kLength), 0.05);
  EXPECT_DOUBLE_EQ(parse_ok("2 in", QuantityKind::kLength), 0.0508);
  EXPECT_DOUBLE_EQ(parse_ok("1.5", QuantityKind::kLength), 1.5);  // bare number: meters
  EXPECT_DOUBLE_EQ(parse_ok("-20cm", QuantityKind::kLength), -0.2);
  EXPECT_DOUBLE_EQ(parse_ok("5um", QuantityKind::kLength), 5e-6);  // a pixel's pitch
  EXPECT_DOUBLE_EQ(parse_ok("3.76µm", QuantityKind::kLength), 3.76e-6);
}

TEST(Units, AnglesConvertToRadians) {
  EXPECT_NEAR(parse_ok("20deg", QuantityKind::kAngle), 20 * std::numbers::pi / 180, 1e-12);
  EXPECT_NEAR(parse_ok("90", QuantityKind::kAngle), std::numbers::pi / 2, 1e-12);
  EXPECT_NEAR(parse_ok("1rad", QuantityKind::kAngle), 1.0, 1e-12);
}

TEST(Units, ShutterFractionsAndSeconds) {
  EXPECT_DOUBLE_EQ(parse_ok("1/125", QuantityKind::kTime), 1.0 / 125);
  EXPECT_DOUBLE_EQ(parse_ok("1/125s", QuantityKind::kTime), 1.0 / 125);
  EXPECT_DOUBLE_EQ(parse_ok("2s", QuantityKind::kTime), 2.0);
  EXPECT_DOUBLE_EQ(parse_ok("30", QuantityKind::kTime), 30.0);
  EXPECT_DOUBLE_EQ(parse_ok("4ms", QuantityKind::kTime), 0.004);
  EXPECT_FALSE(parse_quantity("1/0", QuantityKind::kTime).value);
  EXPECT_FALSE(parse_quantity("1/125m", QuantityKind::kTime).value);
}

TEST(Units, FNumbers) {
  EXPECT_DOUBLE_EQ(parse_ok("f/8", QuantityKind::kFNumber), 8);
  EXPECT_DOUBLE_EQ(parse_ok("F5.6", QuantityKind::kFNumber), 5.6);
  EXPECT_DOUBLE_EQ(parse_ok("11", QuantityKind::kFNumber), 11);
  EXPECT_FALSE(parse_quantity("f/8cm", QuantityKind::kFNumber).value);
}

TEST(Units, LightUnits) {
  EXPECT_DOUBLE_EQ(parse_ok("5600K", QuantityKind::kTemperature), 5600);
  EXPECT_DOUBLE_EQ(parse_ok("400W", QuantityKind::kPower), 400);
  EXPECT_DOUBLE_EQ(parse_ok("1.2kW", QuantityKind::kPower), 1200);
  EXPECT_DOUBLE_EQ(parse_ok("2000lx", QuantityKind::kIlluminance), 2000);
  EXPECT_NEAR(parse_ok("1rpm", QuantityKind::kAngularVelocity), 2 * std::numbers::pi / 60, 1e-12);
  EXPECT_NEAR(parse_ok("10deg/s", QuantityKind::kAngularVelocity), 10 * std::numbers::pi / 180,
              1e-12);
}

TEST(Units, WrongKindNamesBothKinds) {
  QuantityParse parsed = parse_quantity("20deg", QuantityKind::kLength);
  EXPECT_FALSE(parsed.value);
  EXPECT_EQ(parsed.error, "'20deg' is an angle, expected a length (m, cm, mm, in)");
}

TEST(Units, GarbageIsRejected) {
  EXPECT_FALSE(parse_quantity("eighty", QuantityKind::kLength).value);
  EXPECT_FALSE(parse_quantity("80 parsecs", QuantityKind::kLength).value);
  EXPECT_FALSE(parse_quantity("nan", QuantityKind::kLength).value);
  EXPECT_FALSE(parse_quantity("inf", QuantityKind::kNumber).value);
  EXPECT_FALSE(parse_quantity("", QuantityKind::kNumber).value);
}

// std::stod read "0x10cm" as 0x10c = 268 metres; a quantity is a decimal number.
TEST(Units, HexadecimalIsNotANumber) {
  EXPECT_FALSE(parse_quantity("0x10cm", QuantityKind::kLength).value);
  EXPECT_FALSE(parse_quantity("0x10", QuantityKind::kNumber).value);
  EXPECT_FALSE(parse_quantity("0x1p3", QuantityKind::kNumber).value);
  EXPECT_DOUBLE_EQ(parse_ok("+2.5e1cm", QuantityKind::kLength), 0.25);
  EXPECT_DOUBLE_EQ(parse_ok(" 3 m", QuantityKind::kLength), 3);
  EXPECT_DOUBLE_EQ(parse_ok("1 / 125", QuantityKind::kTime), 1.0 / 125);
  EXPECT_FALSE(parse_quantity("+-3", QuantityKind::kNumber).value);
}

// A finite number whose unit makes it overflow is rejected like "inf".
TEST(Units, OverflowAfterTheUnitIsRejected) {
  EXPECT_FALSE(parse_quantity("1e308kW", QuantityKind::kPower).value);
  EXPECT_FALSE(parse_quantity("1e400", QuantityKind::kNumber).value);
  EXPECT_FALSE(parse_quantity("1e308/1e-308", QuantityKind::kTime).value);
}

TEST(Units, FormatsForMessages) {
  EXPECT_EQ(format_quantity(0.8, QuantityKind::kLength), "80cm");
  EXPECT_EQ(format_quantity(0.002, QuantityKind::kLength), "2mm");
  EXPECT_EQ(format_quantity(5e-6, QuantityKind::kLength), "5um");
  EXPECT_EQ(format_quantity(1.0 / 125, QuantityKind::kTime), "1/125s");
  EXPECT_EQ(format_quantity(0.8, QuantityKind::kFNumber), "f/0.8");
}

}  // namespace
}  // namespace rigc
