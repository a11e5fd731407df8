#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <set>
#include <sstream>

#include "assets/primitives.h"
#include "backends/preview/preview_backend.h"
#include "compiler/frontend.h"
#include "dslr/buffer_pool.h"
#include "dslr/exposure.h"
#include "dslr/lens.h"
#include "dslr/optics.h"
#include "run/colmap_text.h"
#include "run/manifest.h"
#include "run/run_folder.h"
#include "scene/studio_scene.h"
#include "tests/scene_fixtures.h"
#include "tests/test_support.h"

namespace rigc::preview {
namespace {

namespace fs = std::filesystem;
using testing::ball_scene;
using testing::compile;
using testing::turntable_ball;

struct Blob {
  double x = 0, y = 0, mass = 0;
  int min_x = 1 << 30, max_x = -1;
};

Blob mask_blob(const dslr::DevelopResult& result) {
  Blob blob;
  for (int y = 0; y < result.height; ++y) {
    for (int x = 0; x < result.width; ++x) {
      if (!result.mask[static_cast<size_t>(y) * result.width + x]) continue;
      blob.x += x + 0.5;
      blob.y += y + 0.5;
      blob.mass += 1;
    }
  }
  blob.x /= blob.mass;
  blob.y /= blob.mass;
  return blob;
}

// Horizontal extent of the pixels brighter than `fraction` of the brightest, on linear signal.
Blob bright_extent(const dslr::DevelopResult& result, double fraction) {
  float peak = 0;
  for (size_t i = 0; i < result.linear.size(); i += 3) peak = std::max(peak, result.linear[i + 1]);
  Blob blob;
  for (int y = 0; y < result.height; ++y) {
    for (int x = 0; x < result.width; ++x) {
      if (result.linear[(static_cast<size_t>(y) * result.width + x) * 3 + 1] > fraction * peak) {
        blob.min_x = std::min(blob.min_x, x);
        blob.max_x = std::max(blob.max_x, x);
      }
    }
  }
  return blob;
}

// The ball's image centre must land where COLMAP's OPENCV model, with the exported intrinsics
// and poses, puts the ball's centre; with strong distortion and off-centre positions.
TEST(Preview, ObjectLandsWhereColmapProjectsIt) {
  ir::Scene scene =
      compile(ball_scene(", distortion: {k1: -0.08, k2: 0.02, p1: 0.001}}",
                         R"(  - pose: {position: [0, -0.5m, 0.505m], look_at: [0.12m, 0, 0.55m]}
  - pose: {position: [0.1m, -0.5m, 0.6m], look_at: [-0.1m, 0, 0.45m]}
  - pose: {position: [0, -0.45m, 0.505m], look_at: [0, 0, 0.505m]}
)"));
  ASSERT_EQ(scene.shots.size(), 3u);
  const double scale = 0.25;
  scene::StudioScene studio = scene::prepare_studio_scene(scene);
  std::string error;
  auto camera = run::output_camera(scene.camera, scale, &error);
  ASSERT_TRUE(camera) << error;
  // The ball's centre in the object frame: COLMAP's world.
  const ir::Vec3 center = (scene.object.bounds_min_object + scene.object.bounds_max_object) / 2;
  for (const auto& shot : scene.shots) {
    dslr::DevelopResult result = render_shot(scene, studio, shot, scale, 1);
    ASSERT_EQ(result.width, camera->width);
    const Blob blob = mask_blob(result);
    ASSERT_GT(blob.mass, 100) << shot.name;
    const ir::Vec2 expected =
        run::project_opencv(camera->params(), run::camera_from_object(shot), center);
    EXPECT_NEAR(blob.x, expected.x(), 0.5) << shot.name;
    EXPECT_NEAR(blob.y, expected.y(), 0.5) << shot.name;
  }
}

double mean_green(const dslr::DevelopResult& result) {
  double sum = 0;
  int count = 0;
  for (size_t i = 0; i < result.mask.size(); ++i) {
    if (!result.mask[i]) continue;
    sum += result.linear[i * 3 + 1];
    ++count;
  }
  return sum / count;
}

TEST(Preview, ExposureFollowsShutterApertureAndIso) {
  auto render_mean = [](const std::string& exposure) {
    std::string text =
        ball_scene("}", "  - pose: {position: [0, -0.3m, 0.505m], look_at: object}\n");
    text.replace(text.find("{aperture: f/8, shutter: 1/125, iso: 200}"), 41, exposure);
    ir::Scene scene = compile(text);
    scene::StudioScene studio = scene::prepare_studio_scene(scene);
    return mean_green(render_shot(scene, studio, scene.shots[0], 0.1, 1));
  };
  const double base = render_mean("{aperture: f/8, shutter: 1/250, iso: 200}");
  ASSERT_GT(base, 0.02);
  ASSERT_LT(base, 0.4);  // far from clipping, so ratios are clean
  EXPECT_NEAR(render_mean("{aperture: f/8, shutter: 1/125, iso: 200}") / base, 2.0, 0.02);
  EXPECT_NEAR(render_mean("{aperture: f/11.3137, shutter: 1/250, iso: 200}") / base, 0.5, 0.01);
  EXPECT_NEAR(render_mean("{aperture: f/8, shutter: 1/250, iso: 400}") / base, 2.0, 0.02);
}

// A white Lambertian ball under a known illuminance has luminance L = ρE/π; its signal must be
// the exposure equation of that L (docs/camera-model.md).
TEST(Preview, AbsoluteSignalMatchesTheExposureEquation) {
  ir::Scene scene =
      compile(ball_scene("}", "  - pose: {position: [0, -0.3m, 0.505m], look_at: object}\n"));
  scene::StudioScene studio = scene::prepare_studio_scene(scene);
  dslr::DevelopResult result = render_shot(scene, studio, scene.shots[0], 0.1, 1);
  const double luminance = 0.9 * 2000 / std::numbers::pi;  // ambient only, albedo 0.9
  const double expected = luminance * dslr::exposure_scale(scene.camera);
  // Vignetting darkens the image only slightly in the centre where the ball is.
  EXPECT_NEAR(mean_green(result) / expected, 1.0, 0.05);
}

// The streak of a ball on a turning table is ω·t·R·f/Z pixels longer than the ball.
// A supersampled frame is the same picture at the same size: the object in the same place and as
// bright, its edges averaged from the finer samples.
TEST(Preview, SupersampledFramesKeepTheirPlaceSizeAndBrightness) {
  const ir::Scene scene = turntable_ball(1, "0deg");
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  const run::RenderedShot plain = render_linear(scene, studio, scene.shots[0], 0.1);
  const run::RenderedShot fine =
      render_linear(scene, studio, scene.shots[0], 0.1, nullptr, {.supersample = 3});
  const dslr::LinearFrame &a = plain.frame, &b = fine.frame;
  ASSERT_EQ(b.width, a.width);
  ASSERT_EQ(b.height, a.height);
  EXPECT_EQ(b.fx, a.fx);
  EXPECT_EQ(b.cx, a.cx);
  ASSERT_EQ(b.mask.size(), a.mask.size());
  ASSERT_EQ(b.depth_m.size(), a.depth_m.size());
  int both = 0, either = 0;
  double sum_a = 0, sum_b = 0;
  for (std::size_t i = 0; i < a.mask.size(); ++i) {
    both += a.mask[i] && b.mask[i];
    either += a.mask[i] || b.mask[i];
    for (int c = 0; c < 3; ++c) {
      sum_a += a.rgb[3 * i + c];
      sum_b += b.rgb[3 * i + c];
    }
  }
  ASSERT_GT(both, 100);
  EXPECT_GT(static_cast<double>(both) / either, 0.97);
  EXPECT_NEAR(sum_b / sum_a, 1.0, 0.02);
}

// Without the specular lobe the lit statue loses light, and no pixel gets brighter but a few
// where the choice between a quad's shared lighting and per-pixel lighting went the other way.
TEST(Preview, LeavingSpecularOutOnlyTakesLightAway) {
  const ir::Scene scene = testing::paper_scene();
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  const auto lit = render_linear(scene, studio, scene.shots[0], 0.05).frame;
  const auto diffuse =
      render_linear(scene, studio, scene.shots[0], 0.05, nullptr, {.specular = false}).frame;
  ASSERT_EQ(lit.rgb.size(), diffuse.rgb.size());
  double lit_sum = 0, diffuse_sum = 0;
  int brighter = 0, values = 0;
  for (std::size_t i = 0; i < lit.rgb.size(); ++i) {
    if (!lit.mask[i / 3]) continue;
    lit_sum += lit.rgb[i];
    diffuse_sum += diffuse.rgb[i];
    ++values;
    brighter += diffuse.rgb[i] > lit.rgb[i] * 1.02f;
  }
  EXPECT_LT(brighter, values / 500) << values;
  EXPECT_LT(diffuse_sum, 0.99 * lit_sum) << diffuse_sum << " " << lit_sum;
}

// Vertex colours are the ball's base colour, interpolated: red over its upper half, blue below,
// in the unlit albedo, where the material's own colour would be grey.
TEST(Preview, VertexColoursColourTheObject) {
  ir::Scene scene = turntable_ball(2, "180deg");
  ir::Mesh& mesh = scene.object.mesh;
  float mid = 0;
  for (const auto& p : mesh.positions) mid += p.z() / static_cast<float>(mesh.positions.size());
  for (const auto& p : mesh.positions) {
    mesh.colors.push_back(p.z() > mid ? Eigen::Vector3f(0.8f, 0.05f, 0.05f)
                                      : Eigen::Vector3f(0.05f, 0.05f, 0.8f));
  }
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  const dslr::LinearFrame albedo = render_albedo(scene, studio, scene.shots[0], 0.05);
  int top = -1, bottom = -1;
  for (int y = 0; y < albedo.height; ++y) {
    for (int x = 0; x < albedo.width; ++x) {
      if (albedo.mask[static_cast<std::size_t>(y) * albedo.width + x] == 0) continue;
      if (top < 0) top = y;
      bottom = y;
    }
  }
  ASSERT_GT(bottom - top, 8) << "the ball is in the frame";
  auto mean_row = [&](int y) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int n = 0;
    for (int x = 0; x < albedo.width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * albedo.width + x;
      if (albedo.mask[i] == 0) continue;
      sum += Eigen::Vector3d(albedo.rgb[3 * i], albedo.rgb[3 * i + 1], albedo.rgb[3 * i + 2]);
      ++n;
    }
    return Eigen::Vector3d(sum / std::max(n, 1));
  };
  const Eigen::Vector3d upper = mean_row(top + 2), lower = mean_row(bottom - 2);
  EXPECT_GT(upper.x(), 5 * upper.z()) << upper.transpose();
  EXPECT_GT(lower.z(), 5 * lower.x()) << lower.transpose();
  EXPECT_LT(upper.y(), 0.1 * upper.x()) << "no grey of the material's own colour";
}

TEST(Preview, MotionBlurLengthMatchesTheTurntableSpeed) {
  auto extent = [](const std::string& speed) {
    ir::Scene scene = compile(ball_scene("}",
                                         "  - turntable: {steps: 1, step: 0deg, speed: " + speed +
                                             ", camera: {distance: 40cm, height: 0.5cm}}\n",
                                         "  translate: [0, -6cm, 0]\n"));
    scene::StudioScene studio = scene::prepare_studio_scene(scene);
    const ir::Shot& shot = scene.shots[0];
    Blob blob = bright_extent(render_shot(scene, studio, shot, 0.25, 1), 0.02);
    return std::pair{blob.max_x - blob.min_x + 1.0, scene};
  };
  auto [still, scene] = extent("0deg/s");
  auto [moving, unused] = extent("300deg/s");
  // The ball's centre is 6 cm from the axis, moving across the view at 34 cm from the camera.
  const double f_px = scene.camera.fx * 0.25;
  const double expected = (300 * std::numbers::pi / 180) * (1.0 / 125) * 0.06 * f_px / 0.34;
  ASSERT_GT(expected, 10);
  EXPECT_NEAR((moving - still) / expected, 1.0, 0.15)
      << "still " << still << " moving " << moving << " expected blur " << expected;
}

TEST(Preview, SameSeedGivesIdenticalImagesOtherSeedDiffers) {
  std::string text = ball_scene("}", "  - pose: {position: [0, -0.3m, 0.505m], look_at: object}\n");
  text.replace(text.find("noise: false"), 12, "noise: true");
  ir::Scene scene = compile(text);
  scene::StudioScene studio = scene::prepare_studio_scene(scene);
  auto a = render_shot(scene, studio, scene.shots[0], 0.1, 7);
  auto b = render_shot(scene, studio, scene.shots[0], 0.1, 7);
  auto c = render_shot(scene, studio, scene.shots[0], 0.1, 8);
  EXPECT_EQ(a.encoded, b.encoded);
  EXPECT_NE(a.encoded, c.encoded);
}

}  // namespace
}  // namespace rigc::preview
