// Edits of a scene file's text at the source spans of its values, so that comments, key order
// and the layout of everything the edit does not touch stay as the user wrote them.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace rigc::studio {

// A value's place in the document: map keys, and list indices as decimal numbers
// ({"studio", "lights", "0", "power"}).
using ScenePath = std::vector<std::string>;

// Whether `value` is text the studio may write as one value: a plain scalar or a flow list of
// plain scalars, on one line, with no character that could start other YAML structure.
bool is_safe_value_text(const std::string& value);

// Whether `key` is one step of a ScenePath: a scene-language key (lowercase letters, digits and
// underscores, starting with a letter or underscore, at most 64) or a list index (digits).
bool is_safe_key_text(const std::string& key);

// `text` with the value at `path` replaced by `value` (is_safe_value_text). A missing key is
// added to the deepest map that exists (in its style: a flow map gets `, key: value`, a block map
// a new line at its keys' indentation). Nullopt with `error` when the text does not parse, the
// path crosses something that is not a map or list, a key is not is_safe_key_text, or the value
// is a block collection.
std::optional<std::string> set_value(const std::string& text, const ScenePath& path,
                                     const std::string& value, std::string* error);

// `text` with `entry` (one flow-style item, e.g. `{pose: {...}}`) appended to the list at `path`.
std::optional<std::string> append_to_list(const std::string& text, const ScenePath& path,
                                          const std::string& entry, std::string* error);

// `text` without item `index` of the block or flow list at `path` (its whole lines when block).
std::optional<std::string> remove_from_list(const std::string& text, const ScenePath& path,
                                            size_t index, std::string* error);

}  // namespace rigc::studio
