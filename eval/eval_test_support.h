// Inputs for the evaluation's tests (eval/*_test.cpp and cli/eval_command_test.cpp): a cube as
// ground truth and small images that pass eval's checks.
#pragma once

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "assets/mesh_io.h"

namespace rigc::eval::test_inputs {

// An axis-aligned cube [-h, h]^3 with outward-facing triangles.
inline void cube(double h, std::vector<Eigen::Vector3f>* v,
                 std::vector<std::array<std::uint32_t, 3>>* t) {
  v->clear();
  t->clear();
  for (int i = 0; i < 8; ++i) {
    v->emplace_back((i & 1 ? h : -h), (i & 2 ? h : -h), (i & 4 ? h : -h));
  }
  // Quads (counter-clockwise seen from outside).
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    t->push_back({std::uint32_t(q[0]), std::uint32_t(q[1]), std::uint32_t(q[2])});
    t->push_back({std::uint32_t(q[0]), std::uint32_t(q[2]), std::uint32_t(q[3])});
  }
}

// A 10 cm cube as a PLY file: a ground truth for the command tests.
inline void write_cube_ply(const std::string& path) {
  std::vector<Eigen::Vector3f> v;
  std::vector<std::array<std::uint32_t, 3>> t;
  cube(0.1, &v, &t);
  ir::Mesh mesh;
  mesh.positions = v;
  mesh.triangles = t;
  std::string error;
  ASSERT_TRUE(write_ply(path, mesh, &error)) << error;
}

// A small grey image in the format its name asks for, which eval's readability check accepts.
inline void write_small_image(const std::string& path, int side = 64) {
  const OIIO::ImageSpec spec(side, side, 3, OIIO::TypeDesc::UINT8);
  const std::vector<unsigned char> pixels(static_cast<std::size_t>(side) * side * 3, 128);
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out && out->open(path, spec)) << path;
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
  ASSERT_TRUE(out->close());
}

}  // namespace rigc::eval::test_inputs
