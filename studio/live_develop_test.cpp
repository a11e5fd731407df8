// The live view's DSLR model with its optics kept gives develop_frame's image.
#include "studio/live_develop.h"

#include <gtest/gtest.h>

#include <cstdlib>

#include "backends/preview/preview_backend.h"
#include "run/run_loop.h"
#include "scene/studio_scene.h"
#include "tests/scene_test_support.h"

namespace rigc::studio {
namespace {

// The largest difference of two 8-bit images' codes.
int max_code_difference(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
  EXPECT_EQ(a.size(), b.size());
  int most = 0;
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    most = std::max(most, std::abs(int(a[i]) - int(b[i])));
  }
  return most;
}

std::vector<std::uint8_t> reference_codes(const ir::Scene& scene, const ir::Shot& shot,
                                          const run::RenderedShot& rendered, double scale) {
  run::RenderSettings settings;
  settings.scale = scale;
  std::string error;
  run::RenderedShot copy = rendered;
  dslr::DevelopResult result =
      run::develop_shot(scene, shot, std::move(copy), settings, false, &error, nullptr);
  if (result.encoded_bytes.empty()) {
    result.encoded_bytes.assign(result.encoded.begin(), result.encoded.end());
  }
  return result.encoded_bytes;
}

TEST(StudioLiveDevelop, KeptOpticsGiveTheDslrModelsImageAfterExposureChanges) {
  ir::Scene scene = testing::small_scene();
  ASSERT_FALSE(scene.shots.empty());
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  const ir::Shot& shot = scene.shots.front();
  const double scale = 0.08;
  auto rendered =
      std::make_shared<const run::RenderedShot>(preview::render_linear(scene, studio, shot, scale));
  LiveDevelop live;
  run::RenderSettings settings;
  settings.scale = scale;
  const double isos[] = {100, 400, 1600};
  for (int i = 0; i < 3; ++i) {
    scene.camera.iso = isos[i];
    scene.camera.shutter_s = i == 2 ? 1.0 / 500 : 1.0 / 125;
    DevelopReport report;
    std::string error;
    const dslr::DevelopResult live_result =
        live.develop(scene.camera, rendered, shot, settings, &report, &error);
    ASSERT_FALSE(live_result.encoded_bytes.empty()) << error;
    EXPECT_EQ(report.reused_optics, i > 0) << "the optics serve every exposure of one frame";
    // Float rounding of the exposure gain may move a code by one.
    EXPECT_LE(max_code_difference(live_result.encoded_bytes,
                                  reference_codes(scene, shot, *rendered, scale)),
              1)
        << "ISO " << isos[i];
  }
  // The aperture changes the depth of field: the optics run again.
  scene.camera.aperture_f_number *= 2;
  DevelopReport report;
  report.reused_optics = true;
  std::string error;
  const dslr::DevelopResult stopped_down =
      live.develop(scene.camera, rendered, shot, settings, &report, &error);
  EXPECT_FALSE(report.reused_optics);
  EXPECT_LE(max_code_difference(stopped_down.encoded_bytes,
                                reference_codes(scene, shot, *rendered, scale)),
            1);
}

}  // namespace
}  // namespace rigc::studio
