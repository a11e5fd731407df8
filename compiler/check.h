// The checking pass: YAML tree -> typed scene description, every problem reported at its location.
#pragma once

#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>

#include "compiler/diagnostics.h"
#include "compiler/spec.h"

namespace rigc {

// Parses YAML text; a syntax error is reported at its location and yields nullopt.
std::optional<YAML::Node> parse_yaml(const std::string& text, const std::string& file,
                                     DiagnosticEngine& diag);

// Checks a parsed scene. Reports every error it finds (not only the first); returns nullopt if any.
// `base_dir` resolves relative mesh paths.
std::optional<spec::SceneSpec> check_scene(const YAML::Node& root, const std::string& file,
                                           const std::string& base_dir, DiagnosticEngine& diag);

}  // namespace rigc
