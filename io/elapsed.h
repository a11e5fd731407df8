// Wall time since a moment, in milliseconds: the figure RigC's stage timings report.
#pragma once

#include <chrono>

namespace rigc::io {

inline double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace rigc::io
