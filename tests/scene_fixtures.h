// Scenes the rendering tests share: compiled from text, with the test failing on any error.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "compiler/frontend.h"
#include "tests/test_support.h"

namespace rigc::testing {

inline ir::Scene compile(const std::string& text) {
  DiagnosticEngine diag;
  std::string messages;
  diag.set_handler([&](const Diagnostic&, const std::string& m) { messages += m; });
  auto scene = compile_scene_text(text, "test.yaml", ".", diag);
  EXPECT_TRUE(scene) << messages;
  return scene ? *scene : ir::Scene{};
}

// A small bright ball on a black stand in a black room: its image is easy to measure.
inline std::string ball_scene(const std::string& camera_extra, const std::string& shots,
                              const std::string& object_extra = "") {
  return R"(rigc: 1
object:
  primitive: {shape: sphere, detail: 5}
  fit: {size: 1cm}
  surface: {pattern: none, color: [0.9, 0.9, 0.9]}
)" + object_extra +
         R"(
studio:
  turntable: {diameter: 2cm, height: 50cm, color: [0, 0, 0]}
  backdrop: {green_screen: false}
  floor: {color: [0, 0, 0]}
  ambient: 2000lx
camera:
  body: canon-6d
  lens: {focal_length: 50mm)" +
         camera_extra + R"(
  exposure: {aperture: f/8, shutter: 1/125, iso: 200}
  effects: {noise: false, depth_of_field: false, diffraction: false}
shots:
)" + shots;
}

// The ball scene with one turntable group of `steps` shots `step` apart, 40 cm away.
inline ir::Scene turntable_ball(int steps, const std::string& step,
                                const std::string& camera_extra = "}") {
  return compile(ball_scene(camera_extra, "  - turntable: {steps: " + std::to_string(steps) +
                                              ", step: " + step +
                                              ", camera: {distance: 40cm, height: 1cm}}\n"));
}

// The paper's capture (scenes/paper-turntable.yaml): statue, speckle, soft shadows, green screen.
inline ir::Scene paper_scene() {
  return compile(read_text(source_path("scenes/paper-turntable.yaml")));
}

}  // namespace rigc::testing
