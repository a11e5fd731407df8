// Atomic writes: a reader never sees half a file, and a crash leaves the old file in place.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

namespace rigc {

// A name for a temporary file in `path`'s folder (so a rename over `path` is atomic): hidden, and
// unique to this process and call. For writers that need a path of their own (a library that
// opens the file itself, or a stream written in chunks); they rename it over `path` when done.
std::filesystem::path temporary_path_beside(const std::filesystem::path& path);

// The file that writing `path` should replace: `path` itself, or the file a symbolic link at
// `path` leads to (the link is kept). Empty, with `error` set (if not null), when something
// other than a regular file is there: a rename over it replaced /dev/stdout with a regular file.
std::filesystem::path file_to_replace(const std::filesystem::path& path, std::string* error);

// Writes the file at `temporary` (a fresh name beside the target); false with `reason` set (a
// short text without the path) when it could not.
using FileWriter = std::function<bool(const std::filesystem::path& temporary, std::string* reason)>;

// Has `write` fill a temporary file beside `path`, then renames it over file_to_replace(path).
// The folder must exist. On any failure (the writer's, an exception, the rename) removes the
// temporary, sets `error` (if not null) to "cannot write PATH: REASON" and returns false.
bool write_atomically(const std::filesystem::path& path, const FileWriter& write,
                      std::string* error);

// Writes `bytes` to a temporary file beside `path` (unique suffix), then renames it over `path`
// (over file_to_replace(path), which it refuses the same way). The folder must exist. On failure
// removes the temporary file, sets `error` (if not null) to one line naming the path and returns
// false. Never throws.
bool write_file_atomically(const std::filesystem::path& path, std::string_view bytes,
                           std::string* error);

}  // namespace rigc
