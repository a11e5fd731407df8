// Text that goes into generated scene files and scripts. Everything that comes from the user
// (paths, names) passes through one of these, so no string can end a literal or a comment early.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace rigc::external {

// A double-quoted Python 3 str literal of UTF-8 text, pure ASCII: printable ASCII stays (except
// '"' and '\\', escaped), everything else becomes \xNN, \uNNNN or \UNNNNNNNN escapes of its code
// point. Invalid UTF-8 bytes become U+FFFD.
std::string python_string_literal(std::string_view utf8);

// A double-quoted POV-Ray 3.7 string literal, or nullopt when the text cannot be written safely
// (POV-Ray has no escape for control characters or non-ASCII in file names): for generated file
// names, which are always plain.
std::optional<std::string> pov_string_literal(std::string_view text);

// Text for a one-line comment in any of the generated files: printable ASCII only, no quotes or
// backslashes (anything else becomes '?'), so a newline cannot end the comment and start code.
std::string comment_text(std::string_view text);

// True for names safe as generated file names and as program arguments: 1..64 characters of
// [A-Za-z0-9_.-], starting with a letter or digit (never an option, never a path).
bool is_plain_file_stem(std::string_view name);

// A number as text that every target language reads back exactly enough (%.9g; finite only:
// NaN and infinities become 0).
std::string number_text(double value);

}  // namespace rigc::external
