// Edits of a scene file's text at the source spans yaml-cpp gives its values, so that comments,
// key order and the layout of everything an edit does not touch stay as the user wrote them.
// The studio (one value, a light, a shot), sweep (a variant's values) and plan (the shots
// section) all edit scene text through these.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace rigc {

// A value's place in the document: map keys, and list indices as decimal numbers
// ({"studio", "lights", "0", "power"}).
using ScenePath = std::vector<std::string>;

// The path a sweep file writes as `camera.exposure.aperture` or `shots[0].turntable.steps`;
// nullopt with `error` set when `text` is not `key(.key|[N])*`.
std::optional<ScenePath> parse_scene_path(const std::string& text, std::string* error);

// Whether `value` is text an editor may write as one value: a plain scalar or a flow list of
// plain scalars, on one line, with no character that could start other YAML structure.
bool is_safe_value_text(const std::string& value);

// Whether `key` is one step of a ScenePath: a scene-language key (lowercase letters, digits and
// underscores, starting with a letter or underscore, at most 64) or a list index (digits).
bool is_safe_key_text(const std::string& key);

// `value` as YAML text that reads back as the same scalar: plain when that is safe, else quoted.
std::string yaml_scalar_text(const std::string& value);

// Where a value is written in the text (0-based byte offsets, 1-based line and column).
struct ValueSpan {
  std::size_t begin = 0, end = 0;
  int line = 0, col = 0;
  bool scalar = false;  // else a flow collection (`[0, 1m, 2]`, `{a: 1}`)
};

// The span of the value at `path`: a scalar or a flow collection written where yaml-cpp marks
// it. Nullopt with `error` set when the text does not parse, the path is missing, or the value
// is in a form an edit cannot replace (block collection, multi-line, anchor, alias or tag).
std::optional<ValueSpan> find_value_span(const std::string& text, const ScenePath& path,
                                         std::string* error);

// `text` with each path's value replaced by its YAML text (yaml_scalar_text, or
// is_safe_value_text). Every path must exist; edits apply from the end so spans stay valid.
// Nullopt with `error` when a path cannot be edited or two paths name the same value.
std::optional<std::string> replace_values(
    const std::string& text, const std::vector<std::pair<ScenePath, std::string>>& values,
    std::string* error);

// `text` with the value at `path` replaced by `value` (is_safe_value_text). A missing key is
// added to the deepest map that exists (in its style: a flow map gets `, key: value`, a block map
// a new line at its keys' indentation). Nullopt with `error` when the text does not parse, the
// path crosses something that is not a map or list, a key is not is_safe_key_text, or the value
// is a block collection.
std::optional<std::string> set_value(const std::string& text, const ScenePath& path,
                                     const std::string& value, std::string* error);

// `text` with `entry` (one flow-style item, e.g. `{pose: {...}}`) appended to the non-empty
// list at `path`, in its style.
std::optional<std::string> append_to_list(const std::string& text, const ScenePath& path,
                                          const std::string& entry, std::string* error);

// `text` without item `index` of the block or flow list at `path` (its whole lines when block).
std::optional<std::string> remove_from_list(const std::string& text, const ScenePath& path,
                                            std::size_t index, std::string* error);

// `text` with the top-level block section `key:` (from its key to the next top-level key;
// comment lines just before that key stay with it) replaced by `section`, which starts with the
// key. Nullopt with `error` set when the text has no block-style top-level `key:`.
std::optional<std::string> replace_section(const std::string& text, const std::string& key,
                                           const std::string& section, std::string* error);

// `text` with `lines` (list items and comments, indented by two) added at the end of the
// top-level section `key:`, indented as its items are.
std::optional<std::string> append_to_section(const std::string& text, const std::string& key,
                                             const std::string& lines, std::string* error);

}  // namespace rigc
