// Bounds on a YAML text's shape, checked from yaml-cpp's event stream before any tree is built:
// aliases share nodes, so a recursive alias or nested ones (a "billion laughs" file) would make
// every walk of the tree loop or repeat a node exponentially, and deep nesting recurses.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

namespace rigc {

// Far beyond any scene: its deepest value is a few levels down.
inline constexpr int kMostYamlDepth = 100;
// The nodes of a document with every alias written out: a scene of the most shots holds under
// 100 000.
inline constexpr std::size_t kMostYamlNodes = 1 << 19;

// Where a text breaks a bound and which (0-based line and column, as yaml-cpp's marks).
struct YamlShapeProblem {
  int line = 0;
  int column = 0;
  std::string message;
};

// The first bound the text's documents break (a recursive alias, too many nodes once aliases are
// written out, nesting deeper than kMostYamlDepth), or nullopt. YAML syntax errors are thrown as
// yaml-cpp's exceptions, as YAML::Load throws them.
std::optional<YamlShapeProblem> yaml_shape_problem(const std::string& text);

}  // namespace rigc
