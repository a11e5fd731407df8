// The IR as JSON (`rigc compile --target ir`), so that any backend bug can be reproduced from it.
#pragma once

#include <nlohmann/json.hpp>

#include "ir/ir.h"

namespace rigc {

// `include_geometry` = false leaves out vertex and triangle arrays (for summaries). Text that is
// not UTF-8 (a file or material name) has its stray bytes replaced by U+FFFD.
nlohmann::json ir_to_json(const ir::Scene& scene, bool include_geometry = true);

}  // namespace rigc
