// Models and primitives built before, kept while their files stay as they were: the studio,
// `sweep` and `plan` compile one scene many times (each camera move in the studio is a compile),
// and a scanned mesh takes up to seconds to load, the statue primitive milliseconds to build.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "assets/mesh_io.h"
#include "assets/primitives.h"

namespace rigc {

// Whether the two functions below keep what they load (off by default: a command that compiles
// its scene once would only pay for the copies). Off also empties what is kept.
void keep_loaded_models(bool keep);

// load_model, or a copy of the model a recent call loaded from the same path, when the file, its
// textures and (for OBJ) the material libraries beside it have the same size and modification
// time as then. Failures are not kept.
std::optional<LoadedModel> load_model_cached(const std::string& path, std::string* error);

// make_primitive, or a copy of a recent call's mesh for the same arguments.
ir::Mesh make_primitive_cached(PrimitiveKind kind, int detail, std::uint32_t seed);

}  // namespace rigc
