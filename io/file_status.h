// Why a file the user named cannot be read, in words for a message: the scene file, a mesh, a
// texture, a photo.
#pragma once

#include <filesystem>
#include <string>

namespace rigc {

// Empty when `path` is a regular file that can be opened for reading; otherwise what is wrong,
// worded to follow the file's name: "does not exist", "is a symbolic link to nothing", "is a loop
// of symbolic links", "is a folder", "is not a regular file (a device, a pipe or a socket)", or
// "cannot be opened: " and the system's reason (permission denied).
std::string why_not_readable(const std::filesystem::path& path);

// True when `path` names nothing at all (not even a dangling symbolic link or a loop), the one
// case where a caller may look for the file elsewhere.
bool names_nothing(const std::filesystem::path& path);

}  // namespace rigc
