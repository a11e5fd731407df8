// load_model's answers for files no reader takes.
#include "assets/mesh_io.h"

#include <gtest/gtest.h>

#include <string>

#include "assets/model_test_support.h"
#include "tests/test_support.h"

namespace rigc::model_testing {
namespace {

using ::rigc::testing::TempDir;

TEST(MeshIoLoad, ReportsMissingAndUnsupportedFiles) {
  expect_load_error("/nonexistent/model.glb", "does not exist");
  expect_load_error("/dev/zero", "is not a regular file");
  expect_load_error(kModels + "3DS/fels.3ds", "unsupported model format '.3ds'");
  TempDir dir;
  write_file(dir.file("garbage.glb"), "this is not a glb file at all");
  expect_load_error(dir.file("garbage.glb"), "could not be read");
  write_file(dir.file("garbage.gltf"), "{ not json");
  expect_load_error(dir.file("garbage.gltf"), "could not be read");
  write_file(dir.file("empty.stl"), "");
  expect_load_error(dir.file("empty.stl"), "");
}

}  // namespace
}  // namespace rigc::model_testing
