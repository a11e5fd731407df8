// Built-in shapes, so demos and tests need no model file. All are centred on the origin with +Z up,
// and about one meter across before `fit`/`scale`.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ir/ir.h"

namespace rigc {

enum class PrimitiveKind { kSphere, kBox, kCylinder, kStatue };

// Names as written in scene files: "sphere", "box", "cylinder", "statue".
std::optional<PrimitiveKind> primitive_from_name(const std::string& name);
std::vector<std::string> primitive_names();

// `detail` is a subdivision level (1..10): higher makes more triangles (statue at 6 is ~100k).
// `seed` varies the statue's displacement. All triangles use material 0; uvs are provided.
// sphere: radius 0.5; box: 1 m cube; cylinder: radius 0.5, height 1; statue: a displaced,
// rock-like figure about 1 m tall and 0.5 m wide with bumps at several scales.
ir::Mesh make_primitive(PrimitiveKind kind, int detail, std::uint32_t seed);

}  // namespace rigc
