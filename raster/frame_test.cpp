#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <random>
#include <set>
#include <sstream>

#include "assets/primitives.h"
#include "compiler/frontend.h"
#include "dslr/buffer_pool.h"
#include "dslr/exposure.h"
#include "dslr/lens.h"
#include "dslr/optics.h"
#include "raster/lighting.h"
#include "raster/rasterizer.h"
#include "run/colmap_text.h"
#include "run/manifest.h"
#include "run/run_folder.h"
#include "scene/studio_scene.h"
#include "tests/scene_fixtures.h"
#include "tests/test_support.h"

namespace rigc::raster {
namespace {

namespace fs = std::filesystem;
using testing::compile;
using testing::paper_scene;

// The frame of one of the scene's shots at `scale` of the sensor, with 1024-texel shadow maps.
raster::FrameRequest shot_request(const ir::Scene& scene, int shot, double scale) {
  raster::FrameRequest request;
  request.world_from_camera = scene.shots[shot].world_from_camera;
  request.turntable_angle_rad = scene.shots[shot].turntable_angle_rad;
  request.canvas = dslr::render_geometry_for(scene.camera, scale);
  request.shadow_map_size = 1024;
  return request;
}

// How far a frame's shading strays from per-pixel lighting's, over the object's pixels or the
// studio's (the masks must agree): the summed difference over the summed per-pixel radiance,
// and each pixel's relative difference, sorted.
struct LightingDifference {
  double mean = 0;
  std::vector<double> relative;
  double percentile(int p) const { return relative[relative.size() * p / 100]; }
};
LightingDifference lighting_difference(const dslr::LinearFrame& shaded,
                                       const dslr::LinearFrame& per_pixel, bool object) {
  LightingDifference out;
  double sum = 0, difference = 0;
  for (size_t p = 0; p < shaded.mask.size(); ++p) {
    if ((shaded.mask[p] != 0) != object) continue;
    double a = 0, b = 0;
    for (int c = 0; c < 3; ++c) {
      a += shaded.rgb[3 * p + c];
      b += per_pixel.rgb[3 * p + c];
    }
    sum += b;
    difference += std::abs(a - b);
    out.relative.push_back(std::abs(a - b) / std::max(b, 1e-6));
  }
  std::sort(out.relative.begin(), out.relative.end());
  out.mean = sum > 0 ? difference / sum : 0;
  return out;
}

// Lights summed once per 2 x 2 quad or interpolated over 4 x 4 blocks of the object (the
// default) against every pixel: on the paper's statue, with its speckle pattern, soft shadows
// and a green screen, the radiance must agree closely, at a small scale (mostly quads) and a
// large one (mostly blocks).
TEST(Raster, QuadLightingMatchesPerPixelLighting) {
  const ir::Scene scene = paper_scene();
  ASSERT_FALSE(scene.shots.empty());
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  for (double scale : {0.15, 0.4}) {
    raster::FrameRequest request = shot_request(scene, 3, scale);
    const dslr::LinearFrame quad = raster::render_frame(scene, studio, request);
    request.per_pixel_lighting = true;
    const dslr::LinearFrame pixel = raster::render_frame(scene, studio, request);
    ASSERT_EQ(quad.rgb.size(), pixel.rgb.size());
    ASSERT_EQ(quad.mask, pixel.mask);
    const LightingDifference d = lighting_difference(quad, pixel, true);
    ASSERT_GT(d.relative.size(), 5000u);
    SCOPED_TRACE(::testing::Message() << "scale " << scale);
    EXPECT_LT(d.mean, 0.01);            // on average within 1 %
    EXPECT_LT(d.percentile(99), 0.08);  // 99 % of pixels within 8 %
    EXPECT_GT(d.mean, 0.0) << "the two paths should not be the same code";
  }
}

// A 4 x 4 block of the statue that fails its light check hands its 16 albedos to the quads
// that shade its pixels instead (see raster::FrameRequest::reuse_block_albedos). They must be the
// albedos the quads would evaluate: the same pixel, the same bytes. At 0.7 scale the speckle is
// fully resolved over much of the statue, so thousands of quads take them.
TEST(Raster, QuadsTakingABlocksAlbedosShadeAsTheirOwn) {
  const ir::Scene scene = paper_scene();
  ASSERT_FALSE(scene.shots.empty());
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  raster::FrameRequest request = shot_request(scene, 3, 0.7);
  raster::RasterTimings reused;
  const dslr::LinearFrame with = raster::render_frame(scene, studio, request, &reused);
  request.reuse_block_albedos = false;
  raster::RasterTimings own;
  const dslr::LinearFrame without = raster::render_frame(scene, studio, request, &own);
  EXPECT_GT(reused.quads_with_block_albedos, 1000);
  EXPECT_EQ(own.quads_with_block_albedos, 0);
  ASSERT_EQ(with.rgb.size(), without.rgb.size());
  std::size_t differing = 0;
  for (std::size_t i = 0; i < with.rgb.size(); ++i) differing += with.rgb[i] != without.rgb[i];
  EXPECT_EQ(differing, 0u);
}

// The renderer hands the depth of field each 16-pixel tile's depth and radiance ranges, taken
// tile by tile (plain studio tiles too) while the pixels are in cache: they must be exactly the
// frame's, and the depth of field given them must equal the one that scans the frame itself.
TEST(Raster, TileRangesAreTheFramesOwnAndTheDepthOfFieldAlike) {
  const ir::Scene scene = paper_scene();
  ASSERT_FALSE(scene.shots.empty());
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  raster::FrameRequest request = shot_request(scene, 3, 0.3);
  const dslr::LinearFrame frame = raster::render_frame(scene, studio, request);
  const dslr::TileRanges& ranges = frame.tile_ranges;
  ASSERT_TRUE(ranges.fits(frame.width, frame.height));
  constexpr int kTile = dslr::TileRanges::kTile;
  const float inf = std::numeric_limits<float>::infinity();
  std::size_t wrong = 0;
  for (int ty = 0; ty < ranges.tiles_y; ++ty) {
    for (int tx = 0; tx < ranges.tiles_x; ++tx) {
      float near = inf, far = 0, lo[3] = {inf, inf, inf}, hi[3] = {-inf, -inf, -inf};
      for (int y = ty * kTile; y < std::min(frame.height, (ty + 1) * kTile); ++y) {
        for (int x = tx * kTile; x < std::min(frame.width, (tx + 1) * kTile); ++x) {
          const std::size_t p = static_cast<std::size_t>(y) * frame.width + x;
          const float z = frame.depth_m[p] > 0 ? frame.depth_m[p] : inf;
          near = std::min(near, z);
          far = std::max(far, z);
          for (int c = 0; c < 3; ++c) {
            lo[c] = std::min(lo[c], frame.rgb[3 * p + c]);
            hi[c] = std::max(hi[c], frame.rgb[3 * p + c]);
          }
        }
      }
      const std::size_t t = static_cast<std::size_t>(ty) * ranges.tiles_x + tx;
      wrong += ranges.near_m[t] != near || ranges.far_m[t] != far;
      for (int c = 0; c < 3; ++c) {
        wrong += ranges.radiance[6 * t + c] != lo[c] || ranges.radiance[6 * t + 3 + c] != hi[c];
      }
    }
  }
  EXPECT_EQ(wrong, 0u);

  const dslr::Intrinsics canvas = frame.intrinsics();
  const double focus = scene.shots[3].focus_distance_m;
  std::vector<float> scanned, given, misled;
  dslr::apply_depth_of_field(scene.camera, focus, canvas, frame.rgb, frame.depth_m, scanned);
  dslr::DepthOfFieldOptions options;
  options.tile_ranges = &ranges;
  dslr::apply_depth_of_field(scene.camera, focus, canvas, frame.rgb, frame.depth_m, given, options);
  ASSERT_EQ(given.size(), scanned.size());
  std::size_t differing = 0;
  for (std::size_t i = 0; i < given.size(); ++i) differing += given[i] != scanned[i];
  EXPECT_EQ(differing, 0u);
  // The ranges are what decides: claiming every tile lies at the focus leaves the frame sharp.
  dslr::TileRanges in_focus = ranges;
  std::fill(in_focus.near_m.begin(), in_focus.near_m.end(), static_cast<float>(focus));
  std::fill(in_focus.far_m.begin(), in_focus.far_m.end(), static_cast<float>(focus));
  options.tile_ranges = &in_focus;
  dslr::apply_depth_of_field(scene.camera, focus, canvas, frame.rgb, frame.depth_m, misled,
                             options);
  EXPECT_EQ(misled, frame.rgb);
  EXPECT_NE(scanned, frame.rgb);
}

// The pipeline blurs in place: the sharp tiles stay untouched and the strips read their
// neighbours' rows from copies kept before any strip writes. The result must be the copying
// blur's, value for value: in full-size windows (coarse levels, the statue's silhouette against
// the blurred green screen, the turntable's rim) and in a whole frame at 0.3 scale.
TEST(Raster, DepthOfFieldInPlaceIsTheCopyingOnesResult) {
  const ir::Scene scene = paper_scene();
  ASSERT_FALSE(scene.shots.empty());
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  const dslr::Intrinsics full = dslr::render_geometry_for(scene.camera, 1.0);
  std::vector<raster::FrameRequest> requests;
  for (const auto& [x, y] : {std::pair{0.5, 0.5}, {0.5, 0.83}, {0.35, 0.3}}) {
    raster::FrameRequest request = shot_request(scene, 3, 1.0);
    request.canvas = full;
    request.canvas.width = 1600;
    request.canvas.height = 1000;
    request.canvas.cx = full.cx - (x * full.width - 800);
    request.canvas.cy = full.cy - (y * full.height - 500);
    requests.push_back(request);
  }
  requests.push_back(shot_request(scene, 3, 0.3));
  const double focus = scene.shots[3].focus_distance_m;
  for (const raster::FrameRequest& request : requests) {
    SCOPED_TRACE(::testing::Message() << request.canvas.width << " x " << request.canvas.height
                                      << ", cx " << request.canvas.cx);
    const dslr::LinearFrame frame = raster::render_frame(scene, studio, request);
    dslr::DepthOfFieldOptions options;
    options.tile_ranges = &frame.tile_ranges;
    std::vector<float> copied;
    dslr::apply_depth_of_field(scene.camera, focus, frame.intrinsics(), frame.rgb, frame.depth_m,
                               copied, options);
    // A spare frame of unrelated values, and none at all (the half-size frame then grows one).
    for (const std::size_t spare_size : {frame.rgb.size(), std::size_t{0}}) {
      std::vector<float> in_place = frame.rgb, spare(spare_size, -1.0f);
      dslr::apply_depth_of_field_in_place(scene.camera, focus, frame.intrinsics(), in_place,
                                          frame.depth_m, spare, options);
      ASSERT_EQ(in_place.size(), copied.size());
      std::size_t differing = 0;
      for (std::size_t i = 0; i < copied.size(); ++i) differing += in_place[i] != copied[i];
      EXPECT_EQ(differing, 0u) << "spare of " << spare_size;
    }
    EXPECT_NE(copied, frame.rgb);
  }
}

// At full resolution the studio planes are lit at sparse corners (every 8 or 16 pixels where
// the light is smooth). Two full-density windows of shot 3: the statue's foot on the turntable
// (contact shadow) and the statue's soft shadow on the green screen, against per-pixel lighting.
TEST(Raster, SparseStudioLightingMatchesPerPixelLighting) {
  const ir::Scene scene = paper_scene();
  ASSERT_FALSE(scene.shots.empty());
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  const dslr::Intrinsics full = dslr::render_geometry_for(scene.camera, 1.0);
  struct Window {
    double x, y;  // centre, as a fraction of the frame
  };
  for (const Window window : {Window{0.5, 0.83}, Window{0.1, 0.65}}) {
    raster::FrameRequest request;
    request.world_from_camera = scene.shots[3].world_from_camera;
    request.turntable_angle_rad = scene.shots[3].turntable_angle_rad;
    request.canvas = full;
    request.canvas.width = 1600;
    request.canvas.height = 1000;
    request.canvas.cx = full.cx - (window.x * full.width - 800);
    request.canvas.cy = full.cy - (window.y * full.height - 500);
    request.shadow_map_size = 2048;
    const dslr::LinearFrame sparse = raster::render_frame(scene, studio, request);
    request.per_pixel_lighting = true;
    const dslr::LinearFrame pixel = raster::render_frame(scene, studio, request);
    ASSERT_EQ(sparse.mask, pixel.mask);
    // Per-pixel lighting also turns the plain tiles off (every tile is rasterized per sample):
    // the same surface must be in front in every pixel.
    std::size_t other_depth = 0;
    for (std::size_t i = 0; i < sparse.depth_m.size(); ++i) {
      other_depth += !(std::abs(sparse.depth_m[i] - pixel.depth_m[i]) <= 1e-4f * pixel.depth_m[i]);
    }
    EXPECT_EQ(other_depth, 0u);
    const LightingDifference d = lighting_difference(sparse, pixel, false);
    ASSERT_GT(d.relative.size(), 100000u);
    SCOPED_TRACE(::testing::Message() << "window " << window.x << ", " << window.y);
    // The means are 0.05 % and 0.16 %, the 95th percentiles 0.7 % and 0.5 % (the second window
    // 0.14 % and 0.47 % before whole tiles were blended from their corners; with the 16 px cells'
    // 1 % tolerance for the tiles too, 0.18 % and 0.54 %). Interpolating 16 px cells whose
    // corners differ by up to 30 % already breaks them (0.22-0.25 %, 4.1 %). The rest of the 99th
    // percentile (9 % at the statue's foot, as with per-pixel corners every 8 px) is the contact
    // shadow's dark core and the turntable's rim at grazing view.
    EXPECT_LT(d.mean, 0.002);
    EXPECT_LT(d.percentile(95), 0.03);
    EXPECT_LT(d.percentile(99), 0.12);
  }
}

// A flat surface cannot shadow itself. A softbox low over a wide turntable top lights it at a
// grazing angle, and its soft shadows search 24 texels around each point, where the top's own
// depth in the light's map falls by several times the bias: compared with the point's depth,
// those texels count as blockers. Compared with the top's plane, none do, and the top takes as
// much light as from a 1 cm light of the same power (the two differ by a few per cent in how
// the box's area spreads its light). Compared with the point's depth, the top kept 63 % (0.9996
// now).
TEST(Raster, AreaLightDoesNotShadowAFlatSurfaceItself) {
  auto top_radiance = [](const std::string& light_size) {
    const ir::Scene scene = compile(R"(rigc: 1
object:
  primitive: {shape: sphere, detail: 4}
  fit: {size: 1cm}
  surface: {pattern: none, color: [0.9, 0.9, 0.9]}
studio:
  turntable: {diameter: 80cm, height: 50cm, color: [0.5, 0.5, 0.5]}
  backdrop: {green_screen: false}
  floor: {color: [0, 0, 0]}
  lights:
    - {type: area, position: [1.5m, 0m, 0.9m], size: [)" +
                                    light_size + ", " + light_size + R"(], power: 80W}
  ambient: 0lx
camera:
  body: canon-6d
  lens: {focal_length: 50mm}
  exposure: {aperture: f/8, shutter: 1/125, iso: 200}
shots:
  - turntable: {steps: 1, step: 20deg, camera: {distance: 40cm, height: 80cm}}
)");
    const scene::StudioScene studio = scene::prepare_studio_scene(scene);
    raster::FrameRequest request = shot_request(scene, 0, 0.1);
    request.shadow_map_size = 2048;
    const dslr::LinearFrame frame = raster::render_frame(scene, studio, request);
    // The middle of the frame, which the top fills, less the ball and its short shadow.
    const int width = frame.width, height = frame.height;
    double sum = 0;
    int count = 0;
    for (int y = height * 3 / 10; y < height * 7 / 10; ++y) {
      for (int x = width * 3 / 10; x < width * 7 / 10; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * width + x;
        if (frame.mask[p] != 0 || std::abs(x - width / 2) < width / 10) continue;
        sum += frame.rgb[3 * p + 1];
        ++count;
      }
    }
    EXPECT_GT(count, 1000);
    return sum / std::max(count, 1);
  };
  const double soft = top_radiance("50cm"), small = top_radiance("1cm");
  ASSERT_GT(small, 0);
  EXPECT_NEAR(soft / small, 1.0, 0.05);
}

// A 20 cm box on a turntable, lit by one light (a YAML flow map) front right, seen head-on from
// 70 cm, a little above the turntable top; its frame at `scale`, with a shadow map of
// `map_size` texels.
dslr::LinearFrame box_frame(const std::string& light, double scale, int map_size) {
  const ir::Scene scene = compile(R"(rigc: 1
object:
  primitive: {shape: box}
  fit: {size: 20cm}
  surface: {pattern: none, color: [0.8, 0.8, 0.8]}
studio:
  turntable: {diameter: 80cm, height: 50cm, color: [0.6, 0.6, 0.6]}
  backdrop: {green_screen: false}
  floor: {color: [0, 0, 0]}
  lights:
    - )" + light + R"(
  ambient: 0lx
camera:
  body: canon-6d
  lens: {focal_length: 50mm}
  exposure: {aperture: f/8, shutter: 1/125, iso: 200}
shots:
  - turntable: {steps: 1, step: 20deg, camera: {distance: 70cm, height: 15cm}}
)");
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  raster::FrameRequest request = shot_request(scene, 0, scale);
  request.shadow_map_size = map_size;
  return raster::render_frame(scene, studio, request);
}

std::string area_light_front_right(const std::string& size) {
  return "{type: area, position: [0.5m, -1.0m, 0.95m], size: [" + size + ", " + size +
         "], power: 80W}";
}

// fn(row, box_left) for each row of box_frame across the turntable top left of the box, where
// the box's shadow falls (70-90 % of the height): `row` its first pixel, `box_left` the box's
// first column (the top lies left of it).
template <typename Fn>
void for_rows_left_of_box(const dslr::LinearFrame& frame, const Fn& fn) {
  for (int y = frame.height * 7 / 10; y < frame.height * 9 / 10; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * frame.width;
    int box_left = 0;
    while (box_left < frame.width / 2 && frame.mask[row + box_left] == 0) ++box_left;
    fn(row, box_left);
  }
}

// A box face lit by a softbox keeps its light down to the turntable top it stands on. In the
// light's map the top in front of the face lies nearer the light than the face's plane, inside
// the soft shadow's 24-texel search, yet below every ray from the face to the light: only texels
// inside the cone from a point to the light can hide part of it. Counting the whole search disc,
// the bottom of the face came out darker than its middle, a false dark line along the foot of
// every lit face. The face's bottom-to-middle ratio must match that under a 1 cm light of the
// same power, whose search stays within a texel or two.
TEST(Raster, SoftboxLightsABoxFaceDownToItsFoot) {
  auto foot_to_middle = [](const std::string& light_size) {
    const dslr::LinearFrame frame = box_frame(area_light_front_right(light_size), 0.15, 2048);
    const int width = frame.width, height = frame.height;
    // Per row, the object's mean radiance over the middle fifth of the frame's columns.
    std::vector<double> row_mean(height, -1);
    int bottom = -1, top = height;
    for (int y = 0; y < height; ++y) {
      double sum = 0;
      int count = 0;
      for (int x = width * 2 / 5; x < width * 3 / 5; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * width + x;
        if (frame.mask[p] == 0) continue;
        sum += frame.rgb[3 * p + 1];
        ++count;
      }
      if (count == width / 5) {
        row_mean[y] = sum / count;
        bottom = std::max(bottom, y);
        top = std::min(top, y);
      }
    }
    // The face fills the middle columns from its top edge to its foot on the turntable top.
    const int rows = bottom - top + 1;
    if (rows < height / 2) {
      ADD_FAILURE() << "the face spans " << rows << " of " << height << " rows";
      return 0.0;
    }
    auto band_mean = [&](int from, int to) {  // rows [from, to]
      double sum = 0;
      for (int y = from; y <= to; ++y) sum += row_mean[y];
      return sum / (to - from + 1);
    };
    const double middle = band_mean(top + rows * 2 / 5, top + rows * 3 / 5);
    const double foot = band_mean(bottom - rows * 3 / 100, bottom);
    EXPECT_GT(middle, 0);
    return foot / middle;
  };
  const double soft = foot_to_middle("50cm"), small = foot_to_middle("1cm");
  // 1.000 with the cone (the face's own falloff cancels out); 0.869 counting the whole disc.
  EXPECT_NEAR(soft / small, 1.0, 0.02);
}

// Burley's diffuse (Blender 3's Principled): Lambert's where light and view are along the
// normal; at grazing light and view, 1/4 of it for a smooth surface, and for a rough one the
// retro-reflection 2 (1 + 1 + 1) on top when light and view coincide.
TEST(Raster, DiffuseIsBurleysAsInPrincipled) {
  for (const float roughness : {0.0f, 0.5f, 1.0f}) {
    EXPECT_FLOAT_EQ(burley_diffuse(1, 1, 1, roughness), 1) << roughness;
  }
  EXPECT_FLOAT_EQ(burley_diffuse(0, 0, 1, 0), 0.25f);
  EXPECT_FLOAT_EQ(burley_diffuse(0, 0, 1, 1), 6.25f);
  // Light and view 60° either side of the normal (l·v = -0.5), roughness 0.8.
  const float f = 0.5f * 0.5f * 0.5f * 0.5f * 0.5f, retro = 0.8f * 0.5f;
  EXPECT_FLOAT_EQ(burley_diffuse(0.5f, 0.5f, -0.5f, 0.8f),
                  (1 - f / 2) * (1 - f / 2) + retro * (2 * f + f * f * (retro - 1)));
}

// The diffuse reflection coverage estimates is the preview's: Lambert's illuminance with light
// and view along the normal, Burley's lobe elsewhere (a rough surface seen and lit from the same
// grazing side reflects more than a Lambertian one would).
TEST(Raster, DiffuseIlluminanceIsShapedByBurleysLobe) {
  ir::Light lamp;
  lamp.type = ir::LightType::kPoint;
  lamp.position = {0, 0, 2};
  lamp.power_w = 10;
  const Vector3f up = Vector3f::UnitZ();
  const float head_on = diffuse_illuminance(lamp, Vector3f::Zero(), up, up, 0.8f).x();
  EXPECT_NEAR(head_on, kLumensPerWatt * 10 / (4 * std::numbers::pi_v<float> * 4), 1e-3f * head_on);
  // The surface tilted 80° away from both the lamp and the eye above it.
  const Vector3f tilted(std::sin(80 * std::numbers::pi_v<float> / 180), 0,
                        std::cos(80 * std::numbers::pi_v<float> / 180));
  const float cos_tilt = tilted.z();
  const float rough = diffuse_illuminance(lamp, Vector3f::Zero(), tilted, up, 1.0f).x();
  const float smooth = diffuse_illuminance(lamp, Vector3f::Zero(), tilted, up, 0.0f).x();
  EXPECT_NEAR(rough, head_on * cos_tilt * burley_diffuse(cos_tilt, cos_tilt, 1, 1.0f),
              1e-3f * rough);
  EXPECT_GT(rough, head_on * cos_tilt * 1.5f);
  EXPECT_LT(smooth, head_on * cos_tilt);
  EXPECT_EQ(diffuse_illuminance(lamp, Vector3f::Zero(), -up, up, 0.8f).x(), 0);
}

// A panel's size: it lights a point on its axis as a Lambertian disc of its area does, 1 / (1 +
// R²/D²) of its centre's light, and widens the highlight it makes by half its angular radius.
TEST(Raster, AnAreaLightsSizeDimsItsLightAndWidensItsHighlight) {
  ir::Light panel;
  panel.type = ir::LightType::kArea;
  panel.position = {0, 0, 2};
  panel.direction = {0, 0, -1};
  panel.power_w = 80;
  panel.size_m = {0.5, 0.5};
  const FrameLight light(panel, Vector3f::Ones());
  LightSample sample;
  ASSERT_TRUE(sample_light(light, Vector3f::Zero(), &sample));
  const double radius2 = 0.25 / std::numbers::pi, distance2 = 4;
  EXPECT_NEAR(sample.illuminance.x(),
              light.scaled_color.x() / distance2 / (1 + radius2 / distance2),
              1e-3 * sample.illuminance.x());
  EXPECT_NEAR(sample.half_vector_spread2, radius2 / (4 * distance2), 1e-7);

  // The peak of the GGX lobe is 1 / (π a²), a² = α² + spread²: a glossy highlight loses most of
  // its peak, a rough one little.
  for (const float roughness : {0.3f, 0.8f}) {
    const float alpha2 = std::pow(roughness, 4.0f);
    const float point = ggx_specular(1, 1, 1, 1, roughness, 0.04f, 0);
    const float wide = ggx_specular(1, 1, 1, 1, roughness, 0.04f, sample.half_vector_spread2);
    EXPECT_NEAR(wide / point, alpha2 / (alpha2 + sample.half_vector_spread2), 1e-4) << roughness;
  }
}

// A 1 cm area light casts the hard shadow a point light in its place casts, right up to the
// contact with the box. Where the cone from a point to such a light is narrower than the
// smallest filter (1.5 texels), the filter's outer taps must still count: with them counted as
// lit, a lit wedge opened between the box's foot and its shadow (0.913 of the point light's
// shadowed pixels then, 0.992 now).
TEST(Raster, SmallAreaLightShadowsLikeAPointLight) {
  auto shadowed_pixels = [](const std::string& light) {
    const dslr::LinearFrame frame = box_frame(light, 0.25, 684);  // a 0.25-scale render's map
    // Shadowed: under half the brightest level of the row's top (its lit part).
    int shadowed = 0, top_pixels = 0;
    for_rows_left_of_box(frame, [&](std::size_t row, int box_left) {
      float brightest = 0;
      for (int x = 0; x < box_left; ++x) {
        brightest = std::max(brightest, frame.rgb[3 * (row + x) + 1]);
      }
      for (int x = 0; x < box_left; ++x) {
        if (!std::isfinite(frame.depth_m[row + x])) continue;
        ++top_pixels;
        shadowed += frame.rgb[3 * (row + x) + 1] < 0.5f * brightest;
      }
    });
    EXPECT_GT(top_pixels, 10000);
    return shadowed;
  };
  const int area = shadowed_pixels(area_light_front_right("1cm"));
  const int point = shadowed_pixels("{type: point, position: [0.5m, -1.0m, 0.95m], power: 80W}");
  ASSERT_GT(point, 1000);
  EXPECT_NEAR(static_cast<double>(area) / point, 1.0, 0.03);
}

// A softbox's penumbra falls off smoothly. The filter's light level moves in steps of one tap:
// 16 taps left 17 levels, bands several pixels wide across the turntable top, with the map's
// texel stairs along each (false features for SfM, where a real penumbra has none).
TEST(Raster, SoftShadowPenumbraIsNotBanded) {
  const dslr::LinearFrame frame =
      box_frame(area_light_front_right("50cm"), 0.5, 1368);  // a 0.5-scale render's map
  // Each step between horizontal neighbours inside the penumbra, over the row's lit level.
  std::vector<double> steps;
  for_rows_left_of_box(frame, [&](std::size_t row, int box_left) {
    float lit = 0;
    for (int x = 0; x < box_left; ++x) lit = std::max(lit, frame.rgb[3 * (row + x) + 1]);
    for (int x = 0; x + 1 < box_left; ++x) {
      const float a = frame.rgb[3 * (row + x) + 1], b = frame.rgb[3 * (row + x + 1) + 1];
      // Both on the top (the backdrop lies far behind it).
      const float za = frame.depth_m[row + x], zb = frame.depth_m[row + x + 1];
      if (!(std::abs(za - zb) < 0.01f * za)) continue;
      if (std::min(a, b) > 0.05f * lit && std::max(a, b) < 0.95f * lit) {
        steps.push_back(std::abs(a - b) / lit);
      }
    }
  });
  ASSERT_GT(steps.size(), 50000u);
  // A band's edge is a step of 1/16 of the light, less where the lighting is interpolated: over
  // 1.5 % for 1.0 % of the pairs with 16 taps, 0.25 % with 64. (The largest steps, in both, were
  // along the penumbra's outer edge near the box's foot: see the next test.)
  const auto banded = std::count_if(steps.begin(), steps.end(), [](double s) { return s > 0.015; });
  EXPECT_LT(static_cast<double>(banded) / steps.size(), 0.005) << banded << " of " << steps.size();
}

// A softbox's penumbra fades out smoothly at its outer edge, also near the box's foot, where the
// blocker is the box's low edge, a few centimetres above the turntable top. Four far taps used to
// declare such points lit without reading anything between them and the point, and the
// penumbra's outer edge became a step from full light to half along a line on the top.
TEST(Raster, SoftShadowFadesOutWithoutAStepNearTheFoot) {
  const dslr::LinearFrame frame =
      box_frame(area_light_front_right("50cm"), 0.5, 1368);  // a 0.5-scale render's map
  float lit = 0;                                             // the top's lit level
  for_rows_left_of_box(frame, [&](std::size_t row, int box_left) {
    for (int x = 0; x < box_left; ++x) lit = std::max(lit, frame.rgb[3 * (row + x) + 1]);
  });
  ASSERT_GT(lit, 0);
  // The largest step between neighbours on the top (across a column or a row), over the lit
  // level, where one of the two lies in the penumbra: in the half of the top next to the box
  // (the other half reaches the turntable's rim), clear of the contact, where the penumbra is
  // narrow and steep (3 % of the width left of the box).
  const int clearance = frame.width * 3 / 100;
  double largest = 0;
  int at_x = -1, at_y = -1, pairs = 0;
  for_rows_left_of_box(frame, [&](std::size_t row, int box_left) {
    for (int x = box_left / 2; x + clearance < box_left; ++x) {
      const std::size_t here = row + x;
      for (const std::size_t next : {here + 1, here + frame.width}) {
        const float a = frame.rgb[3 * here + 1], b = frame.rgb[3 * next + 1];
        const float za = frame.depth_m[here], zb = frame.depth_m[next];
        if (!(std::abs(za - zb) < 0.01f * za)) continue;  // both on the top
        if (std::min(a, b) > 0.95f * lit || std::max(a, b) < 0.05f * lit) continue;
        ++pairs;
        if (std::abs(a - b) / lit > largest) {
          largest = std::abs(a - b) / lit;
          at_x = x;
          at_y = static_cast<int>(row / frame.width);
        }
      }
    }
  });
  ASSERT_GT(pairs, 50000);
  // 0.086 with the four taps (a line along the penumbra's outer edge), 0.041 now.
  EXPECT_LT(largest, 0.06) << "at (" << at_x << ", " << at_y << ")";
}

// A softbox's penumbra is as wide as the light seen from the receiver: a 10 cm ball 1 m in front
// of the backdrop, under a 50 cm softbox 1.4 m away, hides at most a sixth of the light from any
// point of the backdrop, so its shadow there is a faint, wide smudge (as POV-Ray renders it), with
// no dark core. With the penumbra search and filter capped at 24 texels of a fine map (a
// centimetre), the ball cast a dark disc with a sharp rim: in the paper scene, two distinct
// statue shadows on the green screen that the reference renders do not have.
TEST(Raster, WidePenumbraMatchesTheLightsVisibleFraction) {
  const Eigen::Vector3d light(0.4, -1.3, 0.55), ball(0, 0, 0.55);  // ball on a 50 cm stand
  const double ball_radius = 0.05, light_size = 0.5, backdrop_y = 1.0;
  auto frame_with_ball = [&](const std::string& ball_size) {
    const ir::Scene scene = compile(R"(rigc: 1
object:
  primitive: {shape: sphere, detail: 5}
  fit: {size: )" + ball_size + R"(}
  surface: {pattern: none, color: [0.8, 0.8, 0.8]}
studio:
  turntable: {diameter: 1cm, height: 50cm, color: [0.6, 0.6, 0.6]}
  backdrop: {green_screen: {color: [0.8, 0.8, 0.8]}, distance: 1m}
  floor: {color: [0, 0, 0]}
  lights:
    - {type: area, position: [0.4m, -1.3m, 0.55m], size: [50cm, 50cm], power: 80W}
  ambient: 0lx
camera:
  body: canon-6d
  lens: {focal_length: 35mm}
  exposure: {aperture: f/8, shutter: 1/125, iso: 200}
shots:
  - pose: {position: [0, -0.9m, 0.55m], look_at: [0, 0, 0.55m]}
)");
    const scene::StudioScene studio = scene::prepare_studio_scene(scene);
    raster::FrameRequest request = shot_request(scene, 0, 0.15);
    request.shadow_map_size = 1024;
    return raster::render_frame(scene, studio, request);
  };
  // The fraction of the light's square (facing the ball) that the ball hides from backdrop point
  // p, on a 200 x 200 grid of the light; its largest value near where the ball's centre projects.
  const Eigen::Vector3d facing = (ball - light).normalized();
  const Eigen::Vector3d across = facing.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d up = across.cross(facing);
  auto hidden_fraction = [&](const Eigen::Vector3d& p) {
    int hidden = 0;
    constexpr int kGrid = 200;
    for (int i = 0; i < kGrid; ++i) {
      for (int j = 0; j < kGrid; ++j) {
        const Eigen::Vector3d s = light + across * light_size * ((i + 0.5) / kGrid - 0.5) +
                                  up * light_size * ((j + 0.5) / kGrid - 0.5);
        const Eigen::Vector3d ray = (p - s).normalized();
        const double along = (ball - s).dot(ray);
        hidden += (ball - s - ray * along).norm() < ball_radius;
      }
    }
    return static_cast<double>(hidden) / (kGrid * kGrid);
  };
  const Eigen::Vector3d centre_shadow =
      light + (ball - light) * ((backdrop_y - light.y()) / (ball.y() - light.y()));
  double most_hidden = 0;
  for (double dx = -0.05; dx <= 0.05; dx += 0.01) {
    for (double dz = -0.05; dz <= 0.05; dz += 0.01) {
      most_hidden =
          std::max(most_hidden, hidden_fraction(centre_shadow + Eigen::Vector3d(dx, 0, dz)));
    }
  }
  ASSERT_GT(most_hidden, 0.1);
  ASSERT_LT(most_hidden, 0.25);
  // The backdrop's light with the ball over that with a 1 mm ball (the stand alike in both).
  const dslr::LinearFrame with = frame_with_ball("10cm"), without = frame_with_ball("1mm");
  ASSERT_EQ(with.width, without.width);
  double darkest = 1;
  int backdrop_pixels = 0;
  for (std::size_t p = 0; p < with.depth_m.size(); ++p) {
    // On the backdrop (1.9 m away; the ball and stand 0.9 m), wholly, and the same point in
    // both frames (the studio's floor is laid out around the object).
    if (!(with.depth_m[p] > 1.5f && std::abs(with.depth_m[p] - without.depth_m[p]) < 0.001f) ||
        with.mask[p] != 0) {
      continue;
    }
    const float lit = without.rgb[3 * p + 1];
    if (!(lit > 0)) continue;
    ++backdrop_pixels;
    darkest = std::min(darkest, static_cast<double>(with.rgb[3 * p + 1] / lit));
  }
  ASSERT_GT(backdrop_pixels, 100000);
  // 0.831 of the light reaches the darkest point: 0.794 now; 0.0 (a black core) with the search
  // and filter capped at 24 texels, 0.76 with coarse texels weighed whole.
  EXPECT_NEAR(darkest, 1 - most_hidden, 0.05) << "the light's hidden fraction is " << most_hidden;
}

// Every pixel is written, also in the odd last column and row of a canvas (quads and blocks
// that the canvas cuts): in the paper scene every ray meets the studio, so no depth stays
// infinite.
TEST(Raster, OddSizedCanvasHasEveryPixelShaded) {
  const ir::Scene scene = paper_scene();
  ASSERT_FALSE(scene.shots.empty());
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  for (bool per_pixel : {false, true}) {
    raster::FrameRequest request;
    request.world_from_camera = scene.shots[0].world_from_camera;
    request.turntable_angle_rad = scene.shots[0].turntable_angle_rad;
    request.canvas = dslr::sensor_intrinsics(scene.camera, 0.05);
    request.canvas.width = 271;  // odd, and not a multiple of the 32-pixel tiles
    request.canvas.height = 181;
    request.canvas.cx = request.canvas.width / 2.0;
    request.canvas.cy = request.canvas.height / 2.0;
    request.shadow_map_size = 512;
    request.per_pixel_lighting = per_pixel;
    const dslr::LinearFrame frame = raster::render_frame(scene, studio, request);
    int unwritten = 0;
    for (float z : frame.depth_m) unwritten += !std::isfinite(z);
    EXPECT_EQ(unwritten, 0) << (per_pixel ? "per-pixel lighting" : "quad lighting");
  }
}

// Frames take reused buffers from the pool, whose contents are left over from another shot:
// poisoned ones must come back fully overwritten (no NaN radiance, masks 0 or 255, depth set).
TEST(Raster, ReusedBuffersAreFullyOverwritten) {
  const ir::Scene scene = paper_scene();
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  raster::FrameRequest request;
  request.world_from_camera = scene.shots[0].world_from_camera;
  request.turntable_angle_rad = scene.shots[0].turntable_angle_rad;
  request.canvas = dslr::sensor_intrinsics(scene.camera, 0.05);
  request.canvas.width = 1201;  // odd, so that the pool's 1 MB floor holds even for the mask
  request.canvas.height = 901;
  request.canvas.cx = request.canvas.width / 2.0;
  request.canvas.cy = request.canvas.height / 2.0;
  request.shadow_map_size = 512;
  const size_t n = static_cast<size_t>(request.canvas.width) * request.canvas.height;
  dslr::release_pooled_buffers();
  std::vector<float> rgb(3 * n, std::numeric_limits<float>::quiet_NaN());
  std::vector<float> depth(n, std::numeric_limits<float>::quiet_NaN());
  std::vector<std::uint8_t> mask(n, 77);
  const void* poisoned[] = {rgb.data(), depth.data(), mask.data()};
  dslr::recycle(std::move(rgb));
  dslr::recycle(std::move(depth));
  dslr::recycle(std::move(mask));
  const dslr::LinearFrame frame = raster::render_frame(scene, studio, request);
  EXPECT_EQ(frame.rgb.data(), poisoned[0]) << "the frame should have taken the poisoned buffers";
  EXPECT_EQ(frame.depth_m.data(), poisoned[1]);
  EXPECT_EQ(frame.mask.data(), poisoned[2]);
  int bad_rgb = 0, bad_mask = 0, bad_depth = 0;
  for (float v : frame.rgb) bad_rgb += !std::isfinite(v);
  for (std::uint8_t m : frame.mask) bad_mask += m != 0 && m != 255;
  for (float z : frame.depth_m) bad_depth += !(z > 0);
  EXPECT_EQ(bad_rgb, 0);
  EXPECT_EQ(bad_mask, 0);
  EXPECT_EQ(bad_depth, 0);
}

// Coverage pictures shade a plane evenly: a studio plane is split into long thin triangles (the
// turntable's caps), and shading each with its own centroid's view direction drew stripes.
TEST(Raster, FaceColourPicturesShadePlanesEvenly) {
  const ir::Scene scene = paper_scene();
  ASSERT_FALSE(scene.shots.empty());
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  raster::FrameRequest request;
  // From above, so that the turntable's top fills much of the picture.
  const ir::Vec3 eye(0.3, -0.45, 1.3), target(0, 0, 0.75);
  const ir::Vec3 forward = (target - eye).normalized();
  const ir::Vec3 right = forward.cross(ir::Vec3::UnitZ()).normalized();
  const ir::Vec3 down = forward.cross(right);
  request.world_from_camera.block<3, 1>(0, 0) = right;
  request.world_from_camera.block<3, 1>(0, 1) = down;
  request.world_from_camera.block<3, 1>(0, 2) = forward;
  request.world_from_camera.block<3, 1>(0, 3) = eye;
  request.canvas = dslr::sensor_intrinsics(scene.camera, 0.12);
  const std::vector<float> rgb = raster::render_face_colors(scene, studio, request, {});
  const raster::VisibilityBuffer visibility = raster::render_visibility(scene, studio, request);
  const int w = visibility.width, h = visibility.height;
  // Inside one plane: no object, and depth affine along the row (a second difference of ~0).
  auto on_plane = [&](int x, int y) {
    const size_t p = static_cast<size_t>(y) * w + x;
    if (visibility.object_triangle[p] >= 0 || visibility.object_triangle[p + 1] >= 0 ||
        visibility.object_triangle[p - 1] >= 0) {
      return false;
    }
    const float a = visibility.depth_m[p - 1], b = visibility.depth_m[p],
                c = visibility.depth_m[p + 1];
    return std::isfinite(a) && std::isfinite(c) && std::abs(a + c - 2 * b) < 1e-4f * b;
  };
  // Steps between neighbours on one plane: only where the planes' edges blur together (a 1-sample
  // depth test cannot see those), not along every thin triangle's edge.
  int pairs = 0, steps = 0;
  for (int y = 1; y < h - 1; ++y) {
    for (int x = 1; x + 2 < w; ++x) {
      if (!on_plane(x, y) || !on_plane(x + 1, y)) continue;
      const size_t p = 3 * (static_cast<size_t>(y) * w + x);
      steps += std::abs(rgb[p + 3] - rgb[p]) > 0.002f;
      ++pairs;
    }
  }
  ASSERT_GT(pairs, 10000);
  EXPECT_LT(steps, pairs / 200) << steps << " steps over " << pairs << " neighbouring pairs";
}

}  // namespace
}  // namespace rigc::raster
