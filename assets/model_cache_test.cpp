#include "assets/model_cache.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>

#include "assets/model_test_support.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc {
namespace {

namespace fs = std::filesystem;

// An ASCII PLY of one triangle whose first vertex is at x.
std::string triangle_ply(float x) {
  return "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
         "end_header\n" +
         std::to_string(x) + " 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
}

class ModelCache : public ::testing::Test {
 protected:
  void SetUp() override { keep_loaded_models(true); }
  void TearDown() override { keep_loaded_models(false); }
  rigc::testing::TempDir dir_;
};

// A kept model serves while its file stays; a file changed on disk is loaded again.
TEST_F(ModelCache, AModelIsLoadedAgainOnlyWhenItsFileChanged) {
  const std::string path = dir_.file("tri.ply");
  model_testing::write_file(path, triangle_ply(0.25f));
  std::string error;
  const auto first = load_model_cached(path, &error);
  ASSERT_TRUE(first) << error;
  EXPECT_FLOAT_EQ(first->mesh.positions[0].x(), 0.25f);
  const auto again = load_model_cached(path, &error);
  ASSERT_TRUE(again) << error;
  EXPECT_EQ(again->mesh.positions, first->mesh.positions);
  // Another x of as many digits: with the size and time put back, the kept model serves (what
  // shows that one is kept); with a new time, the file is read again.
  const fs::file_time_type written = fs::last_write_time(path);
  model_testing::write_file(path, triangle_ply(0.75f));
  fs::last_write_time(path, written);
  const auto kept = load_model_cached(path, &error);
  ASSERT_TRUE(kept) << error;
  EXPECT_FLOAT_EQ(kept->mesh.positions[0].x(), 0.25f);
  fs::last_write_time(path, written + std::chrono::seconds(2));
  const auto changed = load_model_cached(path, &error);
  ASSERT_TRUE(changed) << error;
  EXPECT_FLOAT_EQ(changed->mesh.positions[0].x(), 0.75f);
  // A file gone is an error again, not the kept model.
  fs::remove(path);
  EXPECT_FALSE(load_model_cached(path, &error));
  EXPECT_THAT(error, HasSubstr("tri.ply"));
}

// A primitive is built once for the same arguments, and is the same mesh as built afresh.
TEST_F(ModelCache, APrimitiveIsTheSameMeshAsBuiltAfresh) {
  const ir::Mesh kept = make_primitive_cached(PrimitiveKind::kStatue, 3, 3);
  const ir::Mesh again = make_primitive_cached(PrimitiveKind::kStatue, 3, 3);
  const ir::Mesh fresh = make_primitive(PrimitiveKind::kStatue, 3, 3);
  EXPECT_EQ(again.positions, fresh.positions);
  EXPECT_EQ(again.triangles, fresh.triangles);
  EXPECT_EQ(kept.positions, fresh.positions);
  const ir::Mesh other = make_primitive_cached(PrimitiveKind::kStatue, 3, 4);
  EXPECT_NE(other.positions, fresh.positions);
}

}  // namespace
}  // namespace rigc
