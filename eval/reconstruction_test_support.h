// A small statue run without a renderer, for the tests of `rigc eval --reconstruction` and of the
// ground truth `rigc render` writes: the scene compiled, its ground truth written as a render
// writes it (run::finish_run's files), and grey images of the camera's size that pass eval's
// checks.
#pragma once

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "compiler/frontend.h"
#include "run/bundler.h"
#include "run/camera_csv.h"
#include "run/colmap_text.h"
#include "run/ground_truth_points.h"
#include "tests/test_support.h"

namespace rigc::eval::test_inputs {

// A speckled statue 25 cm tall, 12 shots 30 degrees apart at two heights.
inline const char* kStatueScene = R"(rigc: 1
name: recon-test
object:
  primitive: {shape: statue, detail: 4, seed: 3}
  fit: {height: 25cm}
  surface: {pattern: speckle, scale: 2mm, contrast: 0.8}
studio:
  backdrop: {green_screen: true}
  lights:
    - {type: area, position: [0.7m, -1.3m, 1.3m], size: [50cm, 50cm], power: 60W}
camera:
  body: canon-6d
  lens: {focal_length: 50mm}
  exposure: {aperture: f/11, shutter: 1/125, iso: 200}
shots:
  - turntable: {steps: 6, step: 60deg, camera: {distance: 70cm, height: 10cm}}
  - turntable: {steps: 6, step: 60deg, start: 30deg, camera: {distance: 70cm, height: 45cm}}
)";

inline constexpr double kStatueScale = 0.05;

struct StatueRun {
  std::filesystem::path dir, scene_file;
  ir::Scene scene;
  std::vector<int> shots;
  run::OutputCamera camera;
  run::GroundTruthPoints points;
};

// Writes DIR/scene.yaml and DIR/run/{images,sparse/*.txt,bundle.out,bundle.list.txt,cameras.csv}.
inline std::optional<StatueRun> make_statue_run(const std::filesystem::path& dir,
                                                int point_samples = 5000) {
  StatueRun r;
  r.dir = dir / "run";
  r.scene_file = dir / "scene.yaml";
  rigc::testing::write_text(r.scene_file.string(), kStatueScene);
  DiagnosticEngine diag;
  std::string messages;
  rigc::testing::capture_diagnostics(diag, messages);
  auto scene = compile_scene_file(r.scene_file.string(), diag);
  if (!scene) {
    ADD_FAILURE() << messages;
    return std::nullopt;
  }
  r.scene = std::move(*scene);
  for (const auto& shot : r.scene.shots) r.shots.push_back(shot.index);
  std::string error;
  auto camera = run::output_camera(r.scene.camera, kStatueScale, &error);
  if (!camera) {
    ADD_FAILURE() << error;
    return std::nullopt;
  }
  r.camera = *camera;
  r.points = run::sample_ground_truth_points(r.scene, r.shots, r.camera, point_samples);
  std::filesystem::create_directories(r.dir / "images");
  const bool written = run::write_colmap_sparse(r.dir / "sparse", r.scene, r.shots, kStatueScale,
                                                &error, &r.points) &&
                       run::write_bundler(r.dir / "bundle.out", r.dir / "bundle.list.txt", r.scene,
                                          r.shots, kStatueScale, r.points, &error) &&
                       run::write_camera_csv(r.dir / "cameras.csv", r.scene, r.shots, &error);
  if (!written) {
    ADD_FAILURE() << error;
    return std::nullopt;
  }
  const OIIO::ImageSpec spec(r.camera.width, r.camera.height, 3, OIIO::TypeDesc::UINT8);
  const std::vector<unsigned char> pixels(
      static_cast<std::size_t>(r.camera.width) * r.camera.height * 3, 128);
  for (const auto& shot : r.scene.shots) {
    const std::string path =
        (r.dir / "images" / run::image_file_name(r.scene.camera, shot)).string();
    auto out = OIIO::ImageOutput::create(path);
    if (!out || !out->open(path, spec) || !out->write_image(OIIO::TypeDesc::UINT8, pixels.data()) ||
        !out->close()) {
      ADD_FAILURE() << "cannot write " << path;
      return std::nullopt;
    }
  }
  return r;
}

}  // namespace rigc::eval::test_inputs
