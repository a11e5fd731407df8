// Photos end to end, through the rigc binary: the paper scene rendered by the preview and by
// Cycles, its images copied as a photographer's card would hold them (no sparse/, masks/ or
// manifest), and evaluated like the run folder they came from, or keyed into masks as eval keys
// photos. SLOW and EXTERNAL (COLMAP, Blender).
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "eval/inputs.h"
#include "eval/photo_masks.h"
#include "eval/silhouette.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc::eval {
namespace {

namespace fs = std::filesystem;
using rigc::testing::run_rigc;
using rigc::testing::source_path;

bool have_colmap() {
  return std::system("colmap -h > /dev/null 2>&1") == 0;
}

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The JPEG without its metadata segments (APP1..APP15: EXIF, XMP, IPTC), its pixels untouched,
// as `exiftool -all=` leaves a photo.
std::string without_metadata(const std::string& jpeg) {
  std::string out = jpeg.substr(0, 2);  // SOI
  std::size_t i = 2;
  while (i + 4 <= jpeg.size() && static_cast<unsigned char>(jpeg[i]) == 0xFF) {
    const auto marker = static_cast<unsigned char>(jpeg[i + 1]);
    if (marker == 0xDA) break;  // start of scan: the rest is image data
    const std::size_t length =
        (static_cast<unsigned char>(jpeg[i + 2]) << 8) | static_cast<unsigned char>(jpeg[i + 3]);
    if (!(marker >= 0xE1 && marker <= 0xEF)) out += jpeg.substr(i, 2 + length);
    i += 2 + length;
  }
  return out + jpeg.substr(i);
}

// Copies the run's images into `to`, stripped of their metadata when asked.
void copy_as_photos(const fs::path& run, const fs::path& to, bool strip) {
  fs::create_directories(to);
  for (const auto& e : fs::directory_iterator(run / "images")) {
    std::string bytes = read_bytes(e.path());
    if (strip) bytes = without_metadata(bytes);
    std::ofstream(to / e.path().filename(), std::ios::binary) << bytes;
  }
}

nlohmann::json eval_json(const fs::path& out) {
  std::ifstream in(out / "eval.json");
  return nlohmann::json::parse(in);
}

// The paper scene with its speckle painted 5 mm instead of 2 mm: at 0.15 (821 x 547 px, a pixel
// about 1.6 mm on the statue) the preview box-filters 2 mm dots as a camera would, to a grey
// that leaves SfM too few features. Returns its path ("" when the scene has changed).
std::string write_paper_scene(const rigc::testing::TempDir& dir) {
  std::string text = rigc::testing::read_text(source_path("scenes/paper-turntable.yaml"));
  const std::size_t speckle = text.find("pattern: speckle, scale: 2mm");
  if (speckle == std::string::npos) return "";
  text.replace(text.find("2mm", speckle), 3, "5mm");
  const std::string scene = dir.file("paper-turntable.yaml");
  rigc::testing::write_text(scene, text);
  return scene;
}

// The paper scene rendered by `render_args` (after the scene), its run folder evaluated, then its
// images as photos with their EXIF and stripped of it with the camera stated: both must register
// every image and measure like the run folder.
void expect_photos_register_like_the_run_folder(const std::vector<std::string>& render_args) {
  rigc::testing::TempDir dir;
  const std::string scene = write_paper_scene(dir);
  ASSERT_FALSE(scene.empty());
  const fs::path run = dir.path() / "run";
  std::vector<std::string> render = {"render", scene, "-o", run.string()};
  render.insert(render.end(), render_args.begin(), render_args.end());
  auto r = run_rigc(render);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_rigc(
      {"eval", run.string(), "-o", (dir.path() / "run_eval").string(), "--samples", "20000"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto run_report = eval_json(dir.path() / "run_eval");
  const double run_std = run_report["signed_distance_mm"]["std"].get<double>();
  const double run_mean_abs = run_report["signed_distance_mm"]["mean_abs"].get<double>();

  // As they came from the camera (RigC's JPEGs carry the EXIF a Canon 6D writes), then stripped
  // with the camera stated.
  for (const bool strip : {false, true}) {
    const fs::path photos = dir.path() / (strip ? "stripped" : "photos");
    const fs::path out = dir.path() / (strip ? "stripped_eval" : "photos_eval");
    copy_as_photos(run, photos, strip);
    std::vector<std::string> args = {"eval", "--photos",   photos.string(), "--scene", scene,
                                     "-o",   out.string(), "--samples",     "20000"};
    if (strip) args.insert(args.end(), {"--camera", "canon-6d,50mm"});
    r = run_rigc(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto report = eval_json(out);
    EXPECT_EQ(report["reconstruction"]["registered_images"], 18) << r.err;
    const double std_mm = report["signed_distance_mm"]["std"].get<double>();
    // The target is the std within 1.15x of the run folder's. COLMAP's threads make two
    // runs on the same pixels, masks and prior differ by more at this scale (1800 points): std
    // 1.24 and 1.73 mm against the run folder's 1.10, a few outliers carrying it (see
    // bench/results.md). The mean |d| is what outliers move little: it is held to 1.15x, the
    // std to the spread. bench/photos_table.sh measures the std at 0.25.
    const double mean_abs = report["signed_distance_mm"]["mean_abs"].get<double>();
    EXPECT_LT(mean_abs, 1.15 * run_mean_abs) << "run folder " << run_mean_abs << " mm";
    EXPECT_LT(std_mm, 1.75 * run_std) << "run folder " << run_std << " mm";
    EXPECT_EQ(report["colmap"]["matching"]["matcher"], "sequential");
    const auto& camera = report["photos"]["cameras"][0];
    EXPECT_NEAR(camera["focal_length_px"].get<double>(), 50 / 35.8 * 821, 1e-6);
    EXPECT_THAT(camera["source"].get<std::string>(), HasSubstr(strip ? "--camera" : "EXIF"));
    EXPECT_EQ(report["photos"]["masks"]["masked_photos"], 18);
    EXPECT_TRUE(fs::exists(out / "masks" / "shot_000.png"));
    EXPECT_TRUE(fs::exists(out / "masks_contact_sheet.png"));
    std::cout << "[ photos   ] " << render_args[1] << ", "
              << (strip ? "stripped, --camera" : "with EXIF") << ": "
              << report["reconstruction"]["registered_images"] << "/18, std " << std_mm
              << " mm against the run folder's " << run_std << " mm\n";
  }
}

TEST(EvalEndToEnd, SlowPaperScenePhotosRegisterLikeTheRunFolder) {
  RIGC_REQUIRE_TOOL(have_colmap(), "colmap");
  expect_photos_register_like_the_run_folder({"--backend", "preview", "--scale", "0.15"});
}

// Cycles' renders as photos: its pixel filter softens the speckle, which the still-background key
// must not take for the turntable (it once did: 52 times the run folder's std). Six shots of the
// ring, the fewest the key takes, keyed as eval --photos keys them, against the masks Cycles
// rendered. Registering all 18 as photos is bench/photos_table.sh's (OUT 0.25 cycles).
TEST(EvalEndToEnd, CyclesRendersAsPhotosKeyToTheirObject) {
  RIGC_REQUIRE_TOOL(std::system("blender --version > /dev/null 2>&1") == 0, "blender");
  rigc::testing::TempDir dir;
  const std::string scene = write_paper_scene(dir);
  ASSERT_FALSE(scene.empty());
  const fs::path run = dir.path() / "run";
  const auto r = run_rigc({"render", scene, "--backend", "cycles", "--scale", "0.15", "--samples",
                           "16", "--shots", "0,3,6,9,12,15", "-o", run.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ImageSet photos;
  photos.dir = run / "images";
  for (int shot = 0; shot < 18; shot += 3) {
    const std::string name = fmt::format("shot_{:03d}.jpg", shot);
    photos.names.push_back(name);
    photos.size[name] = {821, 547};
  }
  PhotoMaskOptions options;
  options.backdrop_color = ir::Vec3(0.0, 0.69, 0.25);  // the scene's green screen, as --scene gives
  options.quiet = true;
  std::ostringstream log;
  std::string error;
  const auto masks = make_photo_masks(photos, options, dir.path() / "eval", log, &error);
  ASSERT_TRUE(masks.has_value()) << error;
  EXPECT_EQ(masks->report["masked_photos"], 6) << log.str();
  for (const std::string& name : photos.names) {
    const std::string stem = fs::path(name).stem().string();
    const auto keyed = read_silhouette(masks->dir / (stem + ".png"), &error);
    const auto rendered = read_silhouette(run / "masks" / (stem + ".png"), &error);
    ASSERT_TRUE(keyed && rendered) << error;
    ASSERT_EQ(keyed->coverage.size(), rendered->coverage.size()) << stem;
    const double iou = silhouette_iou(*keyed, *rendered);
    std::cout << "[ photos   ] cycles " << stem << ": keyed mask IoU " << iou << "\n";
    EXPECT_GT(iou, 0.9) << stem;
  }
  // The renders, their masks and the contact sheet, to look at (RIGC_KEEP_MASKS=dir).
  if (const char* keep = std::getenv("RIGC_KEEP_MASKS")) {
    fs::copy(dir.path(), keep, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  }
}

// The paper's Table 1 in one command: `compare --photos` adds the photos as a row beside the
// renderer's, measured like it.
TEST(EvalEndToEnd, SlowCompareWithPhotosGivesTheRendererAndThePhotosRows) {
  RIGC_REQUIRE_TOOL(have_colmap(), "colmap");
  rigc::testing::TempDir dir;
  const std::string scene = write_paper_scene(dir);
  ASSERT_FALSE(scene.empty());
  const fs::path run = dir.path() / "run";
  auto r =
      run_rigc({"render", scene, "--backend", "preview", "--scale", "0.15", "-o", run.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  copy_as_photos(run, dir.path() / "photos", false);
  const fs::path out = dir.path() / "compare";
  r = run_rigc({"compare", scene, "--backends", "preview", "--scale", "0.15", "--photos",
                (dir.path() / "photos").string(), "-o", out.string(), "--samples", "20000"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("| preview | 18 |"));
  EXPECT_THAT(r.out, HasSubstr("| photos | 18 |"));
  const auto preview = eval_json(out / "preview" / "eval");
  const auto photos = eval_json(out / "photos_eval");
  EXPECT_EQ(preview["reconstruction"]["registered_images"], 18);
  EXPECT_EQ(photos["reconstruction"]["registered_images"], 18);
  EXPECT_LT(photos["signed_distance_mm"]["mean_abs"].get<double>(),
            1.15 * preview["signed_distance_mm"]["mean_abs"].get<double>());
  std::string markdown = rigc::testing::read_text((out / "compare.md").string());
  EXPECT_THAT(markdown, HasSubstr("| photos |"));
}

}  // namespace
}  // namespace rigc::eval
