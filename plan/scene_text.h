// Scene text with its `shots:` section replaced or extended: the rest of the file (comments, key
// order, layout) stays as the user wrote it.
#pragma once

#include <optional>
#include <string>

namespace rigc::plan {

// `text` with the top-level `shots:` section (from its key to the next top-level key; comment
// lines just before that key stay with it) replaced by `shots_section`, which starts with the key.
// Nullopt with `error` set when the text has no block-style top-level `shots:` key.
std::optional<std::string> replace_shots_section(const std::string& text,
                                                 const std::string& shots_section,
                                                 std::string* error);

// `text` with `entries` (lines of list items, indented by two) added at the end of the `shots:`
// list, indented as its items are.
std::optional<std::string> append_to_shots_section(const std::string& text,
                                                   const std::string& entries, std::string* error);

}  // namespace rigc::plan
