// The counts a reconstruction file's header states (PLY elements, PCD points, a binary STL's
// triangles, a PTS file's point count), held to the file's size before a reader allocates for
// them: a 117-byte PCD claiming 100,000,000 points took 9.2 GB.
#pragma once

#include <filesystem>
#include <string>

namespace rigc::eval {

// A PLY property's size in bytes, 0 for a type PLY does not have.
int ply_type_bytes(const std::string& type);

// Empty when the header of the file at `path` (its format from `ext`, lower case with the dot)
// states nothing the file cannot hold; otherwise why, worded to follow the file's name ("announces
// 100000000 points (at least 1600000000 bytes) but holds 40 bytes after its header").
std::string header_overclaims(const std::filesystem::path& path, const std::string& ext);

}  // namespace rigc::eval
