// Lens presets in scene files: a prime's focal length, a zoom's range, the aperture and the
// closest focus the lens allows, and errors at the offending value's line.
#include "compiler/presets.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "compiler/frontend.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc {
namespace {

struct Compiled {
  std::optional<ir::Scene> scene;
  std::string diagnostics;
};

// A small scene with `lens`, `exposure` and `focus` lines 8, 9 and 10, its shots on line 12 at
// `distance` from the object.
Compiled compile_with(const std::string& lens, const std::string& aperture = "f/8",
                      const std::string& focus = "auto", const std::string& distance = "100cm") {
  const std::string text =
      "rigc: 1\n"
      "object:\n"
      "  primitive: sphere\n"
      "  fit: {height: 20cm}\n"
      "  surface: {pattern: speckle}\n"
      "camera:\n"
      "  body: canon-6d\n"
      "  lens: " +
      lens +
      "\n"
      "  exposure: {aperture: " +
      aperture +
      ", shutter: 1/125, iso: 200}\n"
      "  focus: " +
      focus +
      "\n"
      "shots:\n"
      "  - turntable: {steps: 4, step: 90deg, camera: {distance: " +
      distance + ", height: 20cm}}\n";
  DiagnosticEngine diag;
  Compiled out;
  rigc::testing::capture_diagnostics(diag, out.diagnostics);
  out.scene = compile_scene_text(text, "lens.yaml", ".", diag);
  return out;
}

TEST(LensPresets, EveryPresetIsAPlausibleRealLens) {
  ASSERT_GE(lens_presets().size(), 6u);
  for (const LensPreset& lens : lens_presets()) {
    EXPECT_TRUE(find_lens_preset(lens.name)) << lens.name;
    EXPECT_GE(lens.shortest_focal_m, 0.010) << lens.name;
    EXPECT_LE(lens.longest_focal_m, 0.600) << lens.name;
    EXPECT_LE(lens.shortest_focal_m, lens.longest_focal_m) << lens.name;
    EXPECT_GE(lens.widest_f_number, 1.0) << lens.name;
    EXPECT_GT(lens.narrowest_f_number, 4 * lens.widest_f_number) << lens.name;
    EXPECT_GT(lens.min_focus_m, 0.1) << lens.name;
    EXPECT_LT(lens.min_focus_m, 2.0) << lens.name;
    // Each preset compiles at its widest aperture and longest focal length.
    const Compiled c = compile_with(
        "{preset: " + lens.name + ", focal_length: " +
            std::to_string(static_cast<int>(std::lround(lens.longest_focal_m * 1000))) + "mm}",
        "f/" + std::to_string(lens.widest_f_number).substr(0, 3));
    EXPECT_TRUE(c.scene) << lens.name << "\n" << c.diagnostics;
  }
}

TEST(LensPresets, APrimeGivesItsFocalLength) {
  const Compiled c = compile_with("{preset: canon-ef-85mm-f1.8-usm}");
  ASSERT_TRUE(c.scene) << c.diagnostics;
  EXPECT_NEAR(c.scene->camera.focal_length_m, 0.085, 1e-9);
  const Compiled with_length =
      compile_with("{preset: sigma-35mm-f1.4-dg-hsm-art, focal_length: 35mm}");
  ASSERT_TRUE(with_length.scene) << with_length.diagnostics;
  EXPECT_NEAR(with_length.scene->camera.focal_length_m, 0.035, 1e-9);
}

TEST(LensPresets, AZoomTakesAFocalLengthInItsRange) {
  const Compiled c = compile_with("{preset: canon-ef-24-70mm-f2.8l-ii-usm, focal_length: 35mm}");
  ASSERT_TRUE(c.scene) << c.diagnostics;
  EXPECT_NEAR(c.scene->camera.focal_length_m, 0.035, 1e-9);

  const Compiled none = compile_with("{preset: canon-ef-24-70mm-f2.8l-ii-usm}");
  EXPECT_FALSE(none.scene);
  EXPECT_THAT(none.diagnostics, HasSubstr("lens.yaml:8:9: error: the zoom lens "
                                          "canon-ef-24-70mm-f2.8l-ii-usm needs a 'focal_length' in "
                                          "24mm-70mm"));

  const Compiled outside =
      compile_with("{preset: canon-ef-24-105mm-f4l-is-ii-usm, focal_length: 135mm}");
  EXPECT_FALSE(outside.scene);
  EXPECT_THAT(outside.diagnostics, HasSubstr("lens.yaml:8:"));
  EXPECT_THAT(outside.diagnostics, HasSubstr("focal length 135mm is outside the lens "
                                             "canon-ef-24-105mm-f4l-is-ii-usm's 24mm-105mm"));
  // A prime takes no other focal length.
  EXPECT_FALSE(compile_with("{preset: canon-ef-50mm-f1.8-stm, focal_length: 55mm}").scene);
}

TEST(LensPresets, ApertureOutsideTheLensIsAnErrorAtItsLine) {
  const Compiled wide = compile_with("{preset: canon-ef-50mm-f1.8-stm}", "f/1.4");
  EXPECT_FALSE(wide.scene);
  EXPECT_THAT(wide.diagnostics, HasSubstr("lens.yaml:9:24: error: f/1.4 is wider than the lens "
                                          "canon-ef-50mm-f1.8-stm opens (f/1.8 at the widest)"));
  const Compiled narrow = compile_with("{preset: sigma-35mm-f1.4-dg-hsm-art}", "f/22");
  EXPECT_FALSE(narrow.scene);
  EXPECT_THAT(narrow.diagnostics,
              HasSubstr("lens.yaml:9:24: error: f/22 is narrower than the lens "
                        "sigma-35mm-f1.4-dg-hsm-art closes (f/16 at the narrowest)"));
  EXPECT_TRUE(compile_with("{preset: canon-ef-50mm-f1.8-stm}", "f/1.8").scene);
  EXPECT_TRUE(compile_with("{preset: canon-ef-50mm-f1.8-stm}", "f/22").scene);
}

TEST(LensPresets, FocusCloserThanTheLensCanIsAnErrorAtItsLine) {
  const Compiled close = compile_with("{preset: canon-ef-85mm-f1.8-usm}", "f/8", "60cm");
  EXPECT_FALSE(close.scene);
  EXPECT_THAT(close.diagnostics,
              HasSubstr("lens.yaml:10:10: error: focus at 0.6m is closer than the "
                        "lens canon-ef-85mm-f1.8-usm focuses (0.85m at the closest)"));
  EXPECT_TRUE(compile_with("{preset: canon-ef-85mm-f1.8-usm}", "f/8", "90cm").scene);
}

// Autofocus cannot focus closer either: a shot whose subject is nearer is an error at its line.
TEST(LensPresets, AutofocusCloserThanTheLensCanIsAnErrorAtTheShot) {
  const Compiled close = compile_with("{preset: canon-ef-85mm-f1.8-usm}", "f/8", "auto", "80cm");
  EXPECT_FALSE(close.scene);
  EXPECT_THAT(close.diagnostics,
              HasSubstr("lens.yaml:12:5: error: shot_000: the subject is 0.81 m away, "
                        "closer than the lens canon-ef-85mm-f1.8-usm focuses (0.85 m "
                        "at the closest); step back"));
  EXPECT_TRUE(compile_with("{preset: canon-ef-50mm-f1.8-stm}", "f/8", "auto", "80cm").scene);
}

TEST(LensPresets, UnknownPresetSaysWhichAreKnown) {
  const Compiled c = compile_with("{preset: canon-ef-50mm-f1.8-sm}");
  EXPECT_FALSE(c.scene);
  EXPECT_THAT(c.diagnostics,
              HasSubstr("lens.yaml:8:18: error: unknown lens 'canon-ef-50mm-f1.8-sm'"));
  EXPECT_THAT(c.diagnostics, HasSubstr("canon-ef-50mm-f1.8-stm"));
}

}  // namespace
}  // namespace rigc
