// Where something came from in a scene file, kept in the IR so that later stages (the capture
// advice, a backend's errors) can point at the line responsible.
#pragma once

#include <string>

namespace rigc {

// Lines and columns are 1-based; 0 means unknown.
struct SourceLoc {
  std::string file;
  int line = 0;
  int col = 0;
};

}  // namespace rigc
