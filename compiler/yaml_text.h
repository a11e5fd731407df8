// Facts about YAML source text that the tools editing a scene file in place (studio, sweep) need
// beside yaml-cpp's parse: where a token written at a known offset ends.
#pragma once

#include <cstddef>
#include <string>

namespace rigc {

// One past the closing quote of the single- or double-quoted scalar that starts at `pos` ('' and
// \" do not close it), or npos when it is not closed.
std::size_t quoted_scalar_end(const std::string& text, std::size_t pos);

}  // namespace rigc
