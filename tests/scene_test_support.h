// Test helper (header only, not part of the library): a small compiled scene.
#pragma once

#include <gtest/gtest.h>

#include <optional>
#include <string>

#include "compiler/frontend.h"
#include "tests/test_support.h"

namespace rigc::testing {

// A sphere on a turntable, 6 shots, a distorted lens: compiled from text, no files needed.
inline ir::Scene small_scene() {
  static const char* kText = R"(rigc: 1
name: backend-common-test
object:
  primitive: sphere
  fit: {height: 20cm}
  surface: {pattern: speckle}
camera:
  body: canon-6d
  lens: {focal_length: 50mm, distortion: {k1: -0.05, k2: 0.01, p1: 0.001, p2: -0.002}}
  exposure: {aperture: f/8, shutter: 1/125, iso: 200}
shots:
  - turntable: {steps: 6, step: 60deg, camera: {distance: 80cm, height: 20cm}}
)";
  DiagnosticEngine diag;
  std::string messages;
  rigc::testing::capture_diagnostics(diag, messages);
  std::optional<ir::Scene> scene = compile_scene_text(kText, "test.yaml", ".", diag);
  EXPECT_TRUE(scene.has_value()) << messages;
  return scene ? *scene : ir::Scene{};
}

}  // namespace rigc::testing
