#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
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

using ::testing::HasSubstr;

namespace rigc::preview {
namespace {

namespace fs = std::filesystem;
using testing::turntable_ball;

// A run into `dir` at 5 % of the sensor: a few kilobytes a shot.
run::RunOptions small_run(const fs::path& dir) {
  run::RunOptions options;
  options.output_dir = dir;
  options.settings.scale = 0.05;
  return options;
}

// The run loop with the preview backend, as `rigc render --backend preview` runs it.
int run_preview(const ir::Scene& scene, const run::RunOptions& options, std::ostream& log,
                std::vector<run::ShotTiming>* timings = nullptr) {
  PreviewBackend backend;
  return run::run_backend(scene, backend, options, log, timings);
}

TEST(PreviewRun, RunWritesTheLayoutAndResumes) {
  testing::TempDir dir;
  ir::Scene scene = turntable_ball(3, "120deg");
  run::RunOptions options = small_run(dir.path());
  std::ostringstream log;
  ASSERT_EQ(run_preview(scene, options, log), 0) << log.str();
  for (const char* file :
       {"images/shot_000.jpg", "images/shot_002.jpg", "masks/shot_001.png", "sparse/cameras.txt",
        "sparse/images.txt", "sparse/points3D.txt", "transforms.json", "manifest.json"}) {
    EXPECT_TRUE(fs::exists(dir.path() / file)) << file;
  }
  // A rerun renders nothing; a deleted image is rendered again, alone.
  std::vector<run::ShotTiming> timings;
  ASSERT_EQ(run_preview(scene, options, log, &timings), 0);
  ASSERT_EQ(timings.size(), 3u);
  for (const auto& t : timings) EXPECT_TRUE(t.skipped);
  fs::remove(dir.path() / "images/shot_001.jpg");
  timings.clear();
  ASSERT_EQ(run_preview(scene, options, log, &timings), 0);
  EXPECT_TRUE(timings[0].skipped);
  EXPECT_FALSE(timings[1].skipped);
  EXPECT_TRUE(timings[2].skipped);
  EXPECT_TRUE(fs::exists(dir.path() / "images/shot_001.jpg"));
}

// Point-sampled shots have keys of their own: the filtered ones are rendered again over them.
TEST(PreviewRun, PointSampledShotsAreNotTakenForFilteredOnes) {
  testing::TempDir dir;
  ir::Scene scene = turntable_ball(2, "180deg");
  run::RunOptions options = small_run(dir.path());
  std::ostringstream log;
  PreviewBackend point_sampled;
  point_sampled.options.draft_surface = true;
  ASSERT_EQ(run::run_backend(scene, point_sampled, options, log), 0) << log.str();
  std::vector<run::ShotTiming> timings;
  ASSERT_EQ(run_preview(scene, options, log, &timings), 0) << log.str();
  ASSERT_EQ(timings.size(), 2u);
  for (const auto& t : timings) EXPECT_FALSE(t.skipped);
}

// A corrected backend (its output version raised) renders a run's shots again instead of
// taking the ones rendered before the correction as up to date.
TEST(PreviewRun, ShotsRenderedBeforeACorrectionRenderAgain) {
  struct CorrectedPreview : PreviewBackend {
    int output_version() const override { return PreviewBackend::output_version() + 1; }
  };
  testing::TempDir dir;
  ir::Scene scene = turntable_ball(2, "180deg");
  run::RunOptions options = small_run(dir.path());
  std::ostringstream log;
  ASSERT_EQ(run_preview(scene, options, log), 0) << log.str();
  std::vector<run::ShotTiming> timings;
  ASSERT_EQ(run_preview(scene, options, log, &timings), 0) << log.str();
  for (const auto& t : timings) EXPECT_TRUE(t.skipped) << "unchanged: up to date";
  CorrectedPreview corrected;
  timings.clear();
  ASSERT_EQ(run::run_backend(scene, corrected, options, log, &timings), 0) << log.str();
  ASSERT_EQ(timings.size(), 2u);
  for (const auto& t : timings) EXPECT_FALSE(t.skipped);
}

// Asking for the default samples by number is the default: the shots stay up to date.
TEST(PreviewRun, TheDefaultSamplesByNumberAreTheDefault) {
  testing::TempDir dir;
  ir::Scene scene = turntable_ball(2, "180deg");
  run::RunOptions options = small_run(dir.path());
  std::ostringstream log;
  ASSERT_EQ(run_preview(scene, options, log), 0) << log.str();
  options.settings.samples = PreviewBackend().default_samples();
  ASSERT_EQ(options.settings.samples, 1);
  std::vector<run::ShotTiming> timings;
  ASSERT_EQ(run_preview(scene, options, log, &timings), 0) << log.str();
  ASSERT_EQ(timings.size(), 2u);
  for (const auto& t : timings) EXPECT_TRUE(t.skipped);
}

// A run's samples per pixel reach the preview as a square grid of finer pixels (the frame
// RenderOptions::supersample renders); they join the shot key, and grids that are not square or
// would render larger than the sensor are refused before anything is written.
TEST(PreviewRun, SamplesAreASquareGridWithinTheSensor) {
  ir::Scene scene = turntable_ball(2, "180deg");
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  PreviewBackend backend;
  run::RenderSettings settings;
  settings.scale = 0.05;
  settings.samples = 4;
  run::RenderedShot by_samples;
  std::string error;
  ASSERT_TRUE(backend.render(scene, studio, scene.shots[1], settings, {}, &by_samples, &error));
  const run::RenderedShot by_option =
      render_linear(scene, studio, scene.shots[1], 0.05, nullptr, {.supersample = 2});
  EXPECT_EQ(by_samples.frame.rgb, by_option.frame.rgb);
  const run::RenderedShot single = render_linear(scene, studio, scene.shots[1], 0.05);
  EXPECT_NE(by_samples.frame.rgb, single.frame.rgb);

  testing::TempDir dir;
  run::RunOptions options = small_run(dir.path());
  std::ostringstream log;
  options.settings.samples = 4;
  ASSERT_EQ(run_preview(scene, options, log), 0) << log.str();
  std::vector<run::ShotTiming> timings;
  options.settings.samples = 0;
  ASSERT_EQ(run_preview(scene, options, log, &timings), 0) << log.str();
  for (const auto& t : timings) EXPECT_FALSE(t.skipped) << "one sample is another image";

  const auto refused = [&](int samples, double scale) {
    testing::TempDir other;
    run::RunOptions o = small_run(other.path());
    o.settings.samples = samples;
    o.settings.scale = scale;
    std::ostringstream message;
    EXPECT_EQ(run_preview(scene, o, message), 1) << samples << " at " << scale;
    EXPECT_FALSE(fs::exists(other.path() / "manifest.json"));
    return message.str();
  };
  EXPECT_THAT(refused(5, 0.05),
              HasSubstr("a square number of samples per pixel (1, 4, 9, 16, ...), "
                        "not 5"));
  EXPECT_THAT(refused(9, 0.5),
              HasSubstr("larger than the sensor; at this scale it takes at most 4 (2 x "
                        "2)"));
  EXPECT_THAT(refused(4, 2.0), HasSubstr("at most 1 (1 x 1)"));
  EXPECT_THAT(refused(2147395600, 0.01), HasSubstr("2147395600 samples per pixel at scale 0.01"))
      << "46340 x 46340, the largest square an int holds";
}

// A run folder holds one scene's shots (`rigc eval` runs COLMAP on every image in images/): a
// rerun after the scene lost shots, or changed its image format, removes what it no longer makes.
TEST(PreviewRun, RerunRemovesTheShotsAndFilesTheSceneNoLongerMakes) {
  testing::TempDir dir;
  auto scene_with = [](int steps, const char* format) {
    return turntable_ball(steps, "90deg", std::string("}\n  output: {format: ") + format + "}");
  };
  run::RunOptions options = small_run(dir.path());
  std::ostringstream log;
  ASSERT_EQ(run_preview(scene_with(4, "jpeg"), options, log), 0) << log.str();
  ASSERT_TRUE(fs::exists(dir.path() / "images/shot_003.jpg"));
  testing::write_text((dir.path() / "images/mine.jpg").string(), "not the run's");

  ASSERT_EQ(run_preview(scene_with(2, "jpeg"), options, log), 0) << log.str();
  EXPECT_THAT(log.str(),
              HasSubstr("2 shots of an earlier run (shot_002 to shot_003) are no longer"));
  EXPECT_FALSE(fs::exists(dir.path() / "images/shot_002.jpg"));
  EXPECT_FALSE(fs::exists(dir.path() / "masks/shot_003.png"));
  EXPECT_TRUE(fs::exists(dir.path() / "images/shot_001.jpg"));
  EXPECT_TRUE(fs::exists(dir.path() / "images/mine.jpg")) << "only the manifest's files go";
  const auto manifest = run::Manifest::load(dir.path() / "manifest.json");
  EXPECT_EQ(manifest.shots().size(), 2u);

  ASSERT_EQ(run_preview(scene_with(2, "png16"), options, log), 0) << log.str();
  EXPECT_TRUE(fs::exists(dir.path() / "images/shot_000.png"));
  EXPECT_FALSE(fs::exists(dir.path() / "images/shot_000.jpg")) << "the JPEG beside the new PNG";
}

// Two renders into one folder at once each saved their own manifest over the other's.
TEST(PreviewRun, ASecondRenderIntoABusyRunFolderIsRefused) {
  testing::TempDir dir;
  ir::Scene scene = turntable_ball(1, "0deg");
  run::RunOptions options = small_run(dir.path());
  std::ostringstream log;
  {
    run::RunFolderLock other;  // as another rigc process would hold it
    ASSERT_TRUE(other.acquire(dir.path(), log)) << log.str();
    EXPECT_EQ(run_preview(scene, options, log), 1);
    EXPECT_THAT(log.str(), HasSubstr("another rigc is writing to the run folder"));
    EXPECT_FALSE(fs::exists(dir.path() / "manifest.json"));
  }
  EXPECT_EQ(run_preview(scene, options, log), 0) << log.str();
}

// A folder named manifest.json let every shot render, and then the run failed (exit 2).
TEST(PreviewRun, AManifestThatIsNoFileStopsTheRunBeforeItRenders) {
  testing::TempDir dir;
  fs::create_directories(dir.path() / "manifest.json");
  run::RunOptions options = small_run(dir.path());
  std::ostringstream log;
  EXPECT_EQ(run_preview(turntable_ball(1, "0deg"), options, log), 1);
  EXPECT_THAT(log.str(), HasSubstr("manifest.json: it is not a regular file"));
  EXPECT_FALSE(fs::exists(dir.path() / "images/shot_000.jpg"));
}

TEST(PreviewRun, UnwritableOutputIsAUserError) {
  testing::TempDir dir;
  fs::permissions(dir.path(), fs::perms::owner_read | fs::perms::owner_exec);
  if (access(dir.path().c_str(), W_OK) == 0) {
    // Running as root: permissions do not stop us, so use a path under a regular file instead.
    testing::write_text(dir.file("file"), "x");
  }
  ir::Scene scene = turntable_ball(1, "0deg");
  run::RunOptions options = small_run(dir.path() / "file" / "run");
  std::ostringstream log;
  EXPECT_EQ(run_preview(scene, options, log), 1);
  EXPECT_THAT(log.str(), HasSubstr("cannot create the output folder"));
}

TEST(PreviewRun, ANonFiniteScaleIsRejectedBeforeAnythingIsWritten) {
  testing::TempDir dir;
  ir::Scene scene = turntable_ball(1, "0deg");
  for (double scale : {std::numeric_limits<double>::quiet_NaN(),
                       std::numeric_limits<double>::infinity(), 0.0, -0.5}) {
    run::RunOptions options = small_run(dir.path() / "run");
    options.settings.scale = scale;
    std::ostringstream log;
    EXPECT_EQ(run_preview(scene, options, log), 1) << scale;
    EXPECT_THAT(log.str(), HasSubstr("render scale"));
    // The run folder is not even made: a NaN scale used to render and record a shot first.
    EXPECT_FALSE(fs::exists(dir.path() / "run")) << scale;
  }
}

// A real camera reproduced: intrinsics with fx != fy and the principal point off the centre, and
// a pose by COLMAP's quaternion. The ground truth states them as given, and the preview puts the
// ball's centre where K [R | t] projects it.
constexpr int kTwinWidth = 160, kTwinHeight = 120;
constexpr double kTwinFx = 190.4, kTwinFy = 214.7, kTwinCx = 91.7, kTwinCy = 52.1;

// The black room's 3 cm ball on its table, seen from `eye` looking past it: off the optical axis.
std::string twin_ball_scene(const ir::Vec3& eye, const Eigen::Quaterniond& camera_from_world) {
  const Eigen::Quaterniond& q = camera_from_world;
  return fmt::format(R"(rigc: 1
object:
  primitive: {{shape: sphere, detail: 5}}
  fit: {{size: 3cm}}
  surface: {{pattern: none, color: [0.9, 0.9, 0.9]}}
studio:
  turntable: {{diameter: 2cm, height: 50cm, color: [0, 0, 0]}}
  backdrop: {{green_screen: false}}
  floor: {{color: [0, 0, 0]}}
  ambient: 2000lx
camera:
  intrinsics: {{width: {}, height: {}, fx: {}, fy: {}, cx: {}, cy: {}}}
  exposure: {{aperture: f/8, shutter: 1/125, iso: 200}}
  effects: {{noise: false, depth_of_field: false, diffraction: false}}
shots:
  - pose: {{position: [{}, {}, {}], rotation: {{quaternion: [{}, {}, {}, {}]}}}}
)",
                     kTwinWidth, kTwinHeight, kTwinFx, kTwinFy, kTwinCx, kTwinCy, eye.x(), eye.y(),
                     eye.z(), q.w(), q.x(), q.y(), q.z());
}

// camera_from_world of a camera at `eye` looking at `target`, +Z up (OpenCV axes).
Eigen::Matrix3d looking_at(const ir::Vec3& eye, const ir::Vec3& target) {
  const ir::Vec3 forward = (target - eye).normalized();
  const ir::Vec3 right = forward.cross(ir::Vec3::UnitZ()).normalized();
  Eigen::Matrix3d world_from_camera;
  world_from_camera << right, forward.cross(right), forward;
  return world_from_camera.transpose();
}

// The centroid of a mask file's object pixels, pixel centres at +0.5.
std::optional<ir::Vec2> mask_centroid(const fs::path& path) {
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) return std::nullopt;
  const int w = in->spec().width, h = in->spec().height;
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(w) * h);
  if (!in->read_image(0, 0, 0, 1, OIIO::TypeDesc::UINT8, mask.data())) return std::nullopt;
  double sum = 0, u = 0, v = 0;
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      const double m = mask[static_cast<std::size_t>(j) * w + i];
      sum += m, u += m * (i + 0.5), v += m * (j + 0.5);
    }
  }
  if (!(sum > 0)) return std::nullopt;
  return ir::Vec2(u / sum, v / sum);
}

TEST(PreviewRun, GivenIntrinsicsAndRotationReachTheGroundTruthAndTheImage) {
  const ir::Vec3 eye(0.12, -0.42, 0.58);
  const Eigen::Matrix3d r = looking_at(eye, {0.03, 0, 0.5});
  const ir::Scene scene = testing::compile(twin_ball_scene(eye, Eigen::Quaterniond(r)));
  ASSERT_EQ(scene.shots.size(), 1u);
  testing::TempDir dir;
  run::RunOptions options = small_run(dir.path());
  options.settings.scale = 1;
  std::ostringstream log;
  ASSERT_EQ(run_preview(scene, options, log), 0) << log.str();

  EXPECT_THAT(testing::read_text((dir.path() / "sparse/cameras.txt").string()),
              ::testing::HasSubstr(fmt::format("\n1 OPENCV {} {} {} {} {} {} 0 0 0 0\n", kTwinWidth,
                                               kTwinHeight, kTwinFx, kTwinFy, kTwinCx, kTwinCy)));
  // images.txt: the object frame at angle 0 is the world raised to the table, so its rotation is
  // the one given.
  std::ifstream images(dir.path() / "sparse/images.txt");
  std::string line;
  while (std::getline(images, line) && line.rfind('#', 0) == 0) {
  }
  std::istringstream fields(line);
  int id = 0;
  double qw = 0, qx = 0, qy = 0, qz = 0;
  fields >> id >> qw >> qx >> qy >> qz;
  const Eigen::Matrix3d written = Eigen::Quaterniond(qw, qx, qy, qz).toRotationMatrix();
  EXPECT_LT((written - r).cwiseAbs().maxCoeff(), 1e-9) << line;
  EXPECT_FALSE(fs::exists(dir.path() / "bundle.out")) << "Bundler cannot state this camera";
  EXPECT_THAT(log.str(), ::testing::HasSubstr("no bundle.out: Bundler's cameras have one focal"));

  // The ball's centre through K [R | t], against the centroid of its silhouette (the ball is
  // 10 px across: its perspective bias is far below a pixel).
  const ir::Object& ball = scene.object;
  const ir::Vec3 centre = (ir::world_from_object(scene, 0) *
                           ((ball.bounds_min_object + ball.bounds_max_object) / 2).homogeneous())
                              .head<3>();
  const ir::Vec3 p = r * (centre - eye);
  const ir::Vec2 predicted(kTwinFx * p.x() / p.z() + kTwinCx, kTwinFy * p.y() / p.z() + kTwinCy);
  const auto seen = mask_centroid(dir.path() / "masks/shot_000.png");
  ASSERT_TRUE(seen);
  EXPECT_LT((*seen - predicted).norm(), 1.0)
      << "seen " << seen->transpose() << ", predicted " << predicted.transpose();
  // Off the centre by more than the principal point's offset and fx - fy could hide.
  EXPECT_GT((predicted - ir::Vec2(kTwinWidth / 2.0, kTwinHeight / 2.0)).norm(), 10);
}

}  // namespace
}  // namespace rigc::preview
