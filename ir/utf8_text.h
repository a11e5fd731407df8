// Well-formed UTF-8: JSON (the IR, the manifest, `check --json`) holds only UTF-8 text, while file
// names, MTL material names and texture paths can hold any bytes.
#pragma once

#include <string>
#include <string_view>

namespace rigc {

// Whether `text` is well-formed UTF-8 (no overlong forms, surrogates or code points past
// U+10FFFF).
bool valid_utf8(std::string_view text);

// `text` with each byte that does not begin a well-formed sequence replaced by U+FFFD.
std::string valid_utf8_text(std::string_view text);

}  // namespace rigc
