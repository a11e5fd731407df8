// Which shots a run renders (`--shots 0,3,5-7`).
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace rigc::run {

// Parses a selection of shot indices: comma-separated indices and inclusive ranges ("0,3,5-7"),
// spaces allowed around them. "" or "all" select every shot. Returns the sorted unique indices,
// or nullopt with a one-line `error` (naming the valid range 0..N-1) for an index out of range,
// a reversed range or text that is not a selection.
std::optional<std::vector<int>> parse_shot_selection(const std::string& text, int shot_count,
                                                     std::string* error);

}  // namespace rigc::run
