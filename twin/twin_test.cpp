// `rigc twin` on the real temple (tests/real/README.md): its calibrated cameras, its silhouettes
// on black velvet. SLOW (TwinTemple.*: the hull and 16 preview renders); the twin's own
// evaluation by COLMAP is EvalEndToEnd.* (slow and external).
#include "twin/twin.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "eval/camera_files.h"
#include "run/colmap_text.h"
#include "studio/server.h"
#include "studio/session.h"
#include "tests/test_support.h"
#include "twin/twin_render.h"
#include "twin/visual_hull.h"

// After Eigen: httplib brings in <resolv.h>, whose `_res` macro breaks Eigen's headers.
#include <httplib.h>

namespace rigc::twin {
namespace {

namespace fs = std::filesystem;
using rigc::testing::run_rigc;
using rigc::testing::source_path;
using ::testing::HasSubstr;

const std::string kTemple = "tests/real/templeSparseRing";

nlohmann::json read_json(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// One twin of the temple for the tests of this process (made once: about half a minute).
const fs::path& temple_twin() {
  static const rigc::testing::TempDir dir;
  static const fs::path twin = [] {
    const fs::path d = dir.path() / "twin";
    const auto r = run_rigc({"twin", source_path(kTemple), "--reference-cameras",
                             source_path(kTemple + "/templeSR_par.txt"), "-o", d.string()});
    if (r.exit_code != 0) std::cerr << r.err;
    return d;
  }();
  return twin;
}

// The twin's views against the photos: silhouettes, brightness and the hull's size.
void expect_silhouettes_are_the_photos(const fs::path& dir) {
  ASSERT_TRUE(fs::exists(dir / "twin.json"));
  const auto report = read_json(dir / "twin.json");
  const auto& photos = report["comparison"]["photos"];
  ASSERT_EQ(photos.size(), 16u) << report.dump(2);
  for (const auto& p : photos) {
    EXPECT_GE(p["silhouette_iou"].get<double>(), 0.9) << p["photo"];
    // The lights were scaled to the photos: each view within a factor of 2 of its photo (the key
    // shades the baked colours once more: 0.62 to 1.29 measured).
    EXPECT_GT(p["brightness_twin_over_photo"].get<double>(), 0.5) << p["photo"];
    EXPECT_LT(p["brightness_twin_over_photo"].get<double>(), 2.0) << p["photo"];
  }
  // The temple's bounding box (tests/real/templeSparseRing/README.txt) is 10.2 x 16.0 x 7.5 cm:
  // the hull, turned level, is about as large (a hull is never smaller than the object).
  std::vector<double> size = report["hull"]["size_m"];
  std::sort(size.begin(), size.end());
  EXPECT_NEAR(size[0], 0.075, 0.015);
  EXPECT_NEAR(size[1], 0.102, 0.02);
  EXPECT_NEAR(size[2], 0.160, 0.02);
  EXPECT_TRUE(fs::exists(dir / "contact_sheet.png"));
}

// The twin checks clean and its shots are the real cameras.
void expect_a_scene_like_any_other(const fs::path& dir) {
  ASSERT_TRUE(fs::exists(dir / "scene.yaml"));
  const auto check = run_rigc({"check", (dir / "scene.yaml").string()});
  EXPECT_EQ(check.exit_code, 0) << check.err;
  EXPECT_THAT(check.err, ::testing::Not(HasSubstr("error")));
  // The shots reproduce the real cameras: the run's ground truth is the calibration, moved into
  // the object frame; the rotation between them is the same for every photo.
  std::string error;
  const auto truth = run::read_colmap_images(dir / "render" / "sparse" / "images.txt", &error);
  ASSERT_TRUE(truth) << error;
  ASSERT_EQ(truth->size(), 16u);
  const auto calibration =
      eval::read_camera_file(source_path(kTemple + "/templeSR_par.txt"), &error);
  ASSERT_TRUE(calibration) << error;
  // The shots are the photos in name order: shot_000 is templeSR0001.png.
  std::map<std::string, ir::Mat4> shot_pose;
  for (const auto& im : *truth) shot_pose[im.name] = im.camera_from_world;
  std::optional<Eigen::Matrix3d> world_turn;  // object frame -> calibration frame
  for (std::size_t k = 0; k < calibration->images.size(); ++k) {
    const Eigen::Matrix3d real = calibration->images[k].camera_from_world.topLeftCorner<3, 3>();
    const Eigen::Matrix3d twin =
        shot_pose.at(fmt::format("shot_{:03d}.jpg", k)).topLeftCorner<3, 3>();
    const Eigen::Matrix3d turn = real.transpose() * twin;
    if (!world_turn) world_turn = turn;
    EXPECT_LT((turn - *world_turn).cwiseAbs().maxCoeff(), 1e-6) << "shot " << k;
  }
}

// What a user does with a twin: plan more shots, sweep an exposure, open it in the studio and
// capture a view there.
void expect_it_plans_sweeps_and_opens_in_the_studio(const fs::path& dir) {
  const fs::path scene = dir / "scene.yaml";
  const auto plan = run_rigc({"plan", scene.string(), "--rings", "20deg", "--azimuth-step", "90deg",
                              "--visibility-scale", "0.05", "--target", "50%"});
  EXPECT_EQ(plan.exit_code, 0) << plan.err;
  const auto planned = run_rigc({"check", (dir / "scene-plan.yaml").string()});
  EXPECT_EQ(planned.exit_code, 0) << planned.err;
  const auto sweep =
      run_rigc({"sweep", scene.string(), "--vary", "camera.exposure.aperture=f/4,f/16", "--scale",
                "0.05", "-o", (dir / "sweep").string()});
  EXPECT_EQ(sweep.exit_code, 0) << sweep.err;
  EXPECT_THAT(sweep.out + sweep.err, HasSubstr("2/2 variants with results"));

  std::string error;
  auto session = studio::Session::open(scene, &error, dir / "studio");
  ASSERT_TRUE(session) << error;
  studio::StudioServer server(*session, {});
  const int port = server.bind(&error);
  ASSERT_GT(port, 0) << error;
  std::thread serving([&] { server.run(); });
  while (!server.is_running()) std::this_thread::yield();
  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(120);
  client.set_default_headers({{"X-Rigc-Token", server.token()}});
  const auto frame = client.Get("/api/frame?width=320");
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->status, 200) << frame->body;
  EXPECT_GT(std::stod(frame->get_header_value("X-Rigc-Mean")), 0.01) << "a black frame";
  const auto capture = client.Post("/api/capture", "{}", "application/json");
  ASSERT_TRUE(capture);
  EXPECT_EQ(capture->status, 200) << capture->body;
  const auto state = nlohmann::json::parse(client.Get("/api/state")->body);
  EXPECT_EQ(state["shots"].get<int>(), 17);
  server.stop();
  serving.join();
}

// One test, so that one process makes the twin (ctest runs each test in its own): half a minute,
// two and a half under the sanitizers.
TEST(TwinTemple, TheTwinsSilhouettesAreThePhotosAndItIsASceneLikeAnyOther) {
  const fs::path& dir = temple_twin();
  {
    SCOPED_TRACE("the silhouettes");
    expect_silhouettes_are_the_photos(dir);
  }
  {
    SCOPED_TRACE("a scene like any other");
    expect_a_scene_like_any_other(dir);
  }
  SCOPED_TRACE("planned, swept and in the studio");
  expect_it_plans_sweeps_and_opens_in_the_studio(dir);
}

TEST(TwinCommand, BadInputsAreClearErrors) {
  rigc::testing::TempDir dir;
  // Photos of two sizes.
  fs::create_directories(dir.path() / "mixed");
  fs::copy_file(source_path(kTemple + "/templeSR0001.png"), dir.path() / "mixed" / "a.png");
  ASSERT_EQ(std::system(("oiiotool " + source_path(kTemple + "/templeSR0002.png") +
                         " --resize 320x240 -o " + (dir.path() / "mixed" / "b.png").string() +
                         " > /dev/null 2>&1")
                            .c_str()),
            0);
  auto r = run_rigc({"twin", dir.file("mixed"), "--object-height", "20cm", "-o", dir.file("out1")});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_THAT(r.err, HasSubstr("differ in size"));
  // Reference cameras named for other photos.
  r = run_rigc({"twin", source_path(kTemple), "--reference-cameras",
                source_path("tests/real/README.md"), "-o", dir.file("out2")});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  // No scale.
  r = run_rigc({"twin", source_path(kTemple), "-o", dir.file("out3")});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_THAT(r.err, HasSubstr("no scale"));
  // Masks that keep everything: no backdrop.
  fs::create_directories(dir.path() / "white");
  for (int i = 1; i <= 16; ++i) {
    const std::string name = fmt::format("templeSR{:04d}", i);
    ASSERT_EQ(std::system(("oiiotool --pattern constant:color=1 640x480 1 -o " +
                           (dir.path() / "white" / (name + ".png")).string() + " > /dev/null 2>&1")
                              .c_str()),
              0);
  }
  r = run_rigc({"twin", source_path(kTemple), "--reference-cameras",
                source_path(kTemple + "/templeSR_par.txt"), "--masks", dir.file("white"), "-o",
                dir.file("out4"), "--no-render"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_THAT(r.err, HasSubstr("no backdrop"));
}

}  // namespace
}  // namespace rigc::twin

namespace rigc::twin {
namespace {

// eval --photos of `photos` against `reference`, exhaustive (the temple's files are not in ring
// order); its eval.json.
nlohmann::json evaluate_photos(const std::string& photos, const std::string& reference,
                               const fs::path& out) {
  const auto r = run_rigc({"eval", "--photos", photos, "--reference-cameras", reference,
                           "--matcher", "exhaustive", "--allow-partial", "-o", out.string()});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return read_json(out / "eval.json");
}

// The what-if a user runs on a twin (docs/twin.md): 32 views on the real cameras' ring register
// more photos and find more points than the 16 real photos did. (The 16-view twin against the
// photos is bench/twin_table.sh: COLMAP registers the twin's views 16 or 5 of 16 from run to
// run, too bimodal for a test.)
TEST(EvalEndToEnd, ADenserRingOnTheTemplesTwinRegistersMoreThanThePhotos) {
  RIGC_REQUIRE_TOOL(std::system("colmap -h > /dev/null 2>&1") == 0, "colmap");
  rigc::testing::TempDir dir;
  const fs::path twin = dir.path() / "twin";
  auto r = run_rigc({"twin", source_path(kTemple), "--reference-cameras",
                     source_path(kTemple + "/templeSR_par.txt"), "--ring-views", "32", "-o",
                     twin.string()});  // rendered: the lights are scaled to the photos then
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_rigc({"render", (twin / "ring_32.yaml").string(), "-o", dir.file("ring")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto real = evaluate_photos(
      source_path(kTemple), source_path(kTemple + "/templeSR_par.txt"), dir.path() / "real");
  const auto ring = evaluate_photos(dir.file("ring") + "/images", dir.file("ring") + "/sparse",
                                    dir.path() / "ring_eval");
  auto registered = [](const nlohmann::json& j) {
    return j["reconstruction"]["registered_images"].get<int>();
  };
  auto points = [](const nlohmann::json& j) { return j["reconstruction"]["points"].get<double>(); };
  std::cout << "[ twin     ] registered: the 16 photos " << registered(real) << ", 32 ring views "
            << registered(ring) << "; points " << points(real) << ", " << points(ring) << "\n";
  EXPECT_GT(registered(ring), 16);
  EXPECT_GT(points(ring), points(real));
  EXPECT_GT(ring["cameras"]["relative_pose_auc_percent"]["5"].get<double>(),
            real["cameras"]["relative_pose_auc_percent"]["5"].get<double>());
}

}  // namespace
}  // namespace rigc::twin

namespace rigc::twin {
namespace {

// The twin renders in every backend: POV-Ray's and Cycles' masks of one view are the preview's.
TEST(TwinTempleExternal, EveryRendererDrawsTheTwinsSilhouette) {
  const fs::path& dir = temple_twin();
  ASSERT_TRUE(fs::exists(dir / "scene.yaml"));
  for (const std::string backend : {"povray", "cycles"}) {
    const fs::path run = dir / ("render_" + backend);
    const auto r = run_rigc({"render", (dir / "scene.yaml").string(), "--backend", backend,
                             "--shots", "4", "--samples", "16", "-o", run.string()});
    ASSERT_EQ(r.exit_code, 0) << backend << ": " << r.err;
    std::string error;
    const auto mine = read_silhouette(run / "masks" / "shot_004.png", &error);
    const auto preview = read_silhouette(dir / "render" / "masks" / "shot_004.png", &error);
    ASSERT_TRUE(mine && preview) << error;
    EXPECT_GT(silhouette_iou(*mine, *preview), 0.97) << backend;
  }
}

}  // namespace
}  // namespace rigc::twin
