// What the model-loading tests share (gltf_test.cpp, assimp_test.cpp, ply_test.cpp,
// mesh_io_test.cpp): the test models' folder, file writers and the checks of a loaded model.
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "assets/mesh_io.h"

namespace rigc::model_testing {

namespace fs = std::filesystem;
using Eigen::Vector3f;

// The Debian package assimp-testmodels is a build dependency: a missing file is a failure.
inline const std::string kModels = "/usr/share/assimp/models/";

inline void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

template <typename T>
void append(std::string* out, const T& value) {
  out->append(reinterpret_cast<const char*>(&value), sizeof(T));
}

// Loads a model that must load; fails the test with the error otherwise.
inline LoadedModel load_ok(const std::string& path) {
  EXPECT_TRUE(fs::exists(path)) << path << " is missing (is assimp-testmodels installed?)";
  std::string error;
  std::optional<LoadedModel> model = load_model(path, &error);
  EXPECT_TRUE(model.has_value()) << error;
  return model ? std::move(*model) : LoadedModel{};
}

// Loading must fail with one line that starts with the path and contains `expected`.
inline void expect_load_error(const std::string& path, const std::string& expected) {
  SCOPED_TRACE(path);
  std::string error;
  const std::optional<LoadedModel> model = load_model(path, &error);
  EXPECT_FALSE(model.has_value());
  EXPECT_EQ(error.rfind(path + ": ", 0), 0u) << error;
  EXPECT_THAT(error, ::testing::HasSubstr(expected));
  EXPECT_THAT(error, ::testing::Not(::testing::HasSubstr("\n")));
}

// Structural invariants every loaded model satisfies.
inline void expect_consistent(const LoadedModel& m) {
  const ir::Mesh& mesh = m.mesh;
  const std::size_t n = mesh.positions.size();
  ASSERT_GT(mesh.triangles.size(), 0u);
  ASSERT_EQ(mesh.normals.size(), n);
  ASSERT_TRUE(mesh.uvs.empty() || mesh.uvs.size() == n);
  ASSERT_EQ(mesh.triangle_material.size(), mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    for (std::uint32_t i : t) ASSERT_LT(i, n);
  }
  for (std::int32_t mat : mesh.triangle_material) {
    ASSERT_GE(mat, 0);
    ASSERT_LT(static_cast<std::size_t>(mat), m.materials.size());
  }
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_TRUE(mesh.positions[i].allFinite());
    ASSERT_NEAR(mesh.normals[i].norm(), 1.0f, 1e-4f);
  }
  for (const ir::Material& mat : m.materials) {
    if (mat.base_color_texture >= 0) {
      ASSERT_LT(static_cast<std::size_t>(mat.base_color_texture), m.textures.size());
    }
  }
  for (const ir::Texture& tex : m.textures) {
    EXPECT_GT(tex.width, 0);
    EXPECT_GT(tex.height, 0);
    EXPECT_GE(tex.channels, 1);
    EXPECT_LE(tex.channels, 4);
    EXPECT_EQ(tex.pixels.size(), static_cast<std::size_t>(tex.width) * tex.height * tex.channels);
  }
}

inline void bounds(const ir::Mesh& mesh, Vector3f* lo, Vector3f* hi) {
  *lo = mesh.positions[0];
  *hi = mesh.positions[0];
  for (const Vector3f& p : mesh.positions) {
    *lo = lo->cwiseMin(p);
    *hi = hi->cwiseMax(p);
  }
}

inline void expect_unit_box(const ir::Mesh& mesh, float half = 0.5f) {
  Vector3f lo, hi;
  bounds(mesh, &lo, &hi);
  EXPECT_TRUE(lo.isApprox(Vector3f::Constant(-half), 1e-5f)) << lo.transpose();
  EXPECT_TRUE(hi.isApprox(Vector3f::Constant(half), 1e-5f)) << hi.transpose();
}

// For convex shapes around the origin: every normal and every triangle faces outward.
inline void expect_outward(const ir::Mesh& mesh, const Vector3f& centre = Vector3f::Zero()) {
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    EXPECT_GT(mesh.normals[i].dot(mesh.positions[i] - centre), 0) << "vertex " << i;
  }
  for (const auto& t : mesh.triangles) {
    const Vector3f& a = mesh.positions[t[0]];
    const Vector3f face = (mesh.positions[t[1]] - a).cross(mesh.positions[t[2]] - a);
    EXPECT_GT(face.dot(a - centre), 0);
  }
}

}  // namespace rigc::model_testing
