// A scene's text with one scalar value replaced at its source span: the rest of the file (comments,
// layout, key order) stays as written, so a variant is an ordinary scene file.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace rigc::sweep {

// One step of a path into the scene as the schema names it: `camera.exposure.aperture` is three
// keys, `shots[0].turntable.steps` a key, an index, two keys.
struct PathStep {
  std::string key;  // empty for an index
  int index = -1;
};

// The steps of `path`, or nullopt with `error` set when it is not `key(.key|[N])*`.
std::optional<std::vector<PathStep>> parse_value_path(const std::string& path, std::string* error);

// Where a scalar value is written in the text (0-based byte offsets, 1-based line and column).
struct ValueSpan {
  std::size_t begin = 0, end = 0;
  int line = 0, col = 0;
};

// The span of the scalar at `path` in `text` (a YAML scene). Nullopt with `error` set when the
// path does not lead to a scalar the file writes.
std::optional<ValueSpan> find_value_span(const std::string& text, const std::string& path,
                                         std::string* error);

// `value` as YAML text that reads back as the same scalar: plain when that is safe, else quoted.
std::string yaml_scalar_text(const std::string& value);

// `text` with every (path, value) replaced; edits apply from the end so spans stay valid. Nullopt
// with `error` when a path is missing or two paths name the same value.
std::optional<std::string> edit_scene_text(
    const std::string& text, const std::vector<std::pair<std::string, std::string>>& values,
    std::string* error);

}  // namespace rigc::sweep
