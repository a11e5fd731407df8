// Scene text with its `shots:` section replaced: the rest of the file (comments, key order,
// layout) stays as the user wrote it.
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

}  // namespace rigc::plan
