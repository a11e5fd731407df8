#include "analysis/advice.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "compiler/frontend.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;
using ::testing::Not;

namespace rigc::analysis {
namespace {

struct Advised {
  std::vector<Advice> advice;
  std::string text;  // every message, one a line
};

Advised advise(const std::string& scene_text) {
  DiagnosticEngine diag;
  std::string messages;
  rigc::testing::capture_diagnostics(diag, messages);
  const auto scene = compile_scene_text(scene_text, "test.yaml", ".", diag);
  EXPECT_TRUE(scene) << messages;
  if (!scene) return {};
  const scene::StudioScene studio = scene::prepare_studio_scene(*scene);
  CoverageOptions options;
  options.visibility_scale = 0.1;
  const CoverageResult coverage = analyse_coverage(*scene, studio, options);
  Advised out;
  out.advice = capture_advice(*scene, studio, coverage);
  for (const Advice& a : out.advice) out.text += a.message + "\n";
  return out;
}

// A statue lit by one area light from the front left, with some ambient light, on a turning
// or stopped table.
struct Lighting {
  double power_w;
  double ambient_lx;
  std::string shutter;
  std::string aperture = "f/8";
  std::string speed;  // turntable speed during the exposure; empty: stopped
};

std::string scene_text(const Lighting& l) {
  const std::string speed = l.speed.empty() ? "" : ", speed: " + l.speed;
  return fmt::format(R"(rigc: 1
object:
  primitive: {{shape: statue, detail: 3}}
  fit: {{height: 30cm}}
  surface: {{pattern: speckle, scale: 3mm}}
studio:
  turntable: {{diameter: 40cm, height: 75cm}}
  lights:
    - {{type: area, position: [0.8m, -0.8m, 1.2m], size: [30cm, 30cm], power: {}W}}
  ambient: {}lx
camera:
  body: canon-6d
  lens: {{focal_length: 50mm}}
  exposure: {{aperture: {}, shutter: {}, iso: 200}}
shots:
  - turntable: {{steps: 8, step: 45deg{}, camera: {{distance: 90cm, height: 30cm}}}}
)",
                     l.power_w, l.ambient_lx, l.aperture, l.shutter, speed);
}

// Whether one advice suggests a change another one reverses; says which in *why.
bool contradicts(const std::vector<Advice>& advice, std::string* why) {
  for (const Advice& a : advice) {
    for (const Advice& b : advice) {
      for (const SettingChange& c : a.changes) {
        const SettingChange reverse{c.setting, -c.direction};
        if (std::find(b.changes.begin(), b.changes.end(), reverse) != b.changes.end()) {
          *why = "'" + a.message + "'\n  against\n'" + b.message + "'";
          return true;
        }
      }
    }
  }
  return false;
}

// One light and little ambient light: the lit side clips where the shadow side is too dark. The
// advice names the range, not two opposite exposure changes.
TEST(Advice, ABrightnessRangeWiderThanTheSensorIsNamedNotTwoOppositeExposures) {
  const Advised a = advise(scene_text({400, 0.5, "1/30", "f/8", ""}));
  EXPECT_THAT(a.text, Not(HasSubstr("over-exposure")));
  EXPECT_THAT(a.text, Not(HasSubstr("under-exposure")));
  EXPECT_THAT(a.text, HasSubstr("the scene's brightness range is wider than the sensor records"));
  EXPECT_THAT(a.text, HasSubstr("add fill light"));
  EXPECT_THAT(a.text, HasSubstr("bracket"));
  // More ambient light narrows the range: then one exposure fits.
  const Advised lit = advise(scene_text({400, 2000, "1/30", "f/8", ""}));
  EXPECT_THAT(lit.text, Not(HasSubstr("brightness range")));
}

// A turning table pins a short shutter; the under-exposure advice then does not lengthen it.
TEST(Advice, UnderExposureOnATurningTableDoesNotLengthenTheShutter) {
  const Advised a = advise(scene_text({20, 300, "1/250", "f/8", "10deg/s"}));
  ASSERT_THAT(a.text, HasSubstr("the turning table smears"));
  ASSERT_THAT(a.text, HasSubstr("under-exposure"));
  EXPECT_THAT(a.text, Not(HasSubstr("lengthen the shutter")));
  std::string why;
  EXPECT_FALSE(contradicts(a.advice, &why)) << why;
}

// The change an advice works out, by setting (a default one where it offers none).
SettingChange change_of(const Advised& a, const std::string& message_part, Setting setting) {
  for (const Advice& advice : a.advice) {
    if (advice.message.find(message_part) == std::string::npos) continue;
    for (const SettingChange& c : advice.changes) {
      if (c.setting == setting) return c;
    }
  }
  return {setting, 0, 0};
}

// The values the advice works out fix what it names: the shutter it gives stops the smear, and
// the ISO it gives lifts the surface out of the dark.
TEST(Advice, SuggestedValuesFixWhatTheyName) {
  const Advised turning = advise(scene_text({400, 300, "1/60", "f/8", "10deg/s"}));
  const SettingChange shutter = change_of(turning, "the turning table smears", Setting::kShutter);
  ASSERT_GT(shutter.value, 0) << turning.text;
  EXPECT_LT(shutter.value, 1.0 / 60);
  const std::string faster = fmt::format("1/{:.0f}", 1 / shutter.value);
  const Advised sharp = advise(scene_text({400, 300, faster, "f/8", "10deg/s"}));
  EXPECT_THAT(sharp.text, Not(HasSubstr("the turning table smears")));

  const Advised dark = advise(scene_text({20, 300, "1/250", "f/8", ""}));
  const SettingChange iso = change_of(dark, "under-exposure", Setting::kIso);
  ASSERT_GT(iso.value, 200) << dark.text;
  std::string brighter = scene_text({20, 300, "1/250", "f/8", ""});
  brighter.replace(brighter.find("iso: 200"), 8, fmt::format("iso: {:.0f}", iso.value));
  const Advised lifted = advise(brighter);
  EXPECT_THAT(lifted.text, Not(HasSubstr("under-exposure")));
}

// Over a family of scenes (light power, ambient light, shutter, aperture, table speed), no
// advice suggests a change another reverses, and over- and under-exposure never come together.
TEST(Advice, NoAdviceReversesAnotherOverAFamilyOfScenes) {
  int over = 0, under = 0, range = 0, blur = 0, diffraction = 0;
  for (const double power : {5.0, 400.0}) {
    for (const double ambient : {0.5, 300.0}) {
      for (const char* shutter : {"1/2000", "1/60", "2"}) {
        for (const char* aperture : {"f/4", "f/64"}) {
          for (const char* speed : {"", "30deg/s"}) {
            const Lighting l{power, ambient, shutter, aperture, speed};
            const Advised a = advise(scene_text(l));
            const std::string name = fmt::format("{} W, {} lx, {} s, {}, '{}'", power, ambient,
                                                 shutter, aperture, speed);
            std::string why;
            EXPECT_FALSE(contradicts(a.advice, &why)) << name << ":\n" << why;
            const bool has_over = a.text.find("over-exposure") != std::string::npos;
            const bool has_under = a.text.find("under-exposure") != std::string::npos;
            EXPECT_FALSE(has_over && has_under) << name << ":\n" << a.text;
            over += has_over;
            under += has_under;
            range += a.text.find("brightness range") != std::string::npos;
            blur += a.text.find("turning table smears") != std::string::npos;
            diffraction += a.text.find("diffraction-limited") != std::string::npos;
          }
        }
      }
    }
  }
  // The family reaches every kind of exposure advice and the settings they could reverse.
  EXPECT_GT(over, 0);
  EXPECT_GT(under, 0);
  EXPECT_GT(range, 0);
  EXPECT_GT(blur, 0);
  EXPECT_GT(diffraction, 0);
}

// Shutter suggestions are speeds a camera has.
// A ring of 8 at 45 degrees overlaps enough of the seen surface, but no view has a neighbour
// near enough for its features to match (the verdict benchmark's 8 steps fail, 18 pass): the
// advice names the shot at its line; 18 steps of 20 degrees get none.
TEST(Advice, AViewWithoutANearNeighbourIsPointedOut) {
  const std::string wide = scene_text({400, 20, "1/125", "f/8", ""});
  const Advised a = advise(wide);
  EXPECT_THAT(a.text, HasSubstr("shot_000's nearest other view is 44 deg away"));  // 30 cm up
  const auto spacing = std::find_if(a.advice.begin(), a.advice.end(), [](const Advice& advice) {
    return advice.message.find("nearest other view") != std::string::npos;
  });
  ASSERT_NE(spacing, a.advice.end());
  EXPECT_EQ(spacing->loc.line, 16);  // the turntable entry
  std::string close = wide;
  close.replace(close.find("steps: 8, step: 45deg"), 21, "steps: 18, step: 20deg");
  EXPECT_THAT(advise(close).text, Not(HasSubstr("nearest other view")));
}

// ISO 25600 at the paper scene's exposure (f/22, 1/4000 s) leaves the median pixel about 40
// electrons: the preview's reconstruction degrades there (the verdict benchmark) and check says
// why at the ISO; ISO 800 at the same exposure (1/500 s at f/13) is quiet.
TEST(Advice, AHighIsoMakingUpForLittleLightIsNamedAtTheIso) {
  const std::string paper =
      rigc::testing::read_text(rigc::testing::source_path("scenes/paper-turntable.yaml"));
  const std::string exposure = "{aperture: f/13, shutter: 1/125, iso: 200}";
  std::string noisy = paper;
  noisy.replace(noisy.find(exposure), exposure.size(),
                "{aperture: f/22, shutter: 1/4000, iso: 25600}");
  const Advised a = advise(noisy);
  EXPECT_THAT(a.text, HasSubstr("sensor noise at ISO 25600"));
  std::string quiet = paper;
  quiet.replace(quiet.find(exposure), exposure.size(),
                "{aperture: f/13, shutter: 1/500, iso: 800}");
  EXPECT_THAT(advise(quiet).text, Not(HasSubstr("sensor noise at ISO")));
}

TEST(Advice, ShutterSuggestionsAreCamerasSpeeds) {
  EXPECT_DOUBLE_EQ(next_faster_standard_shutter(1.0 / 250), 1.0 / 250);
  EXPECT_DOUBLE_EQ(next_faster_standard_shutter(1.0 / 252), 1.0 / 320);
  EXPECT_DOUBLE_EQ(next_faster_standard_shutter(0.7), 1.0 / 1.6);
  EXPECT_DOUBLE_EQ(next_faster_standard_shutter(1.0 / 9000), 1.0 / 8000);
}

}  // namespace
}  // namespace rigc::analysis
