// Atomic writes: a reader never sees half a file, and a crash leaves the old file in place.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace rigc {

// A name for a temporary file in `path`'s folder (so a rename over `path` is atomic): hidden, and
// unique to this process and call. For writers that need a path of their own (a library that
// opens the file itself, or a stream written in chunks); they rename it over `path` when done.
std::filesystem::path temporary_path_beside(const std::filesystem::path& path);

// Writes `bytes` to a temporary file beside `path` (unique suffix), then renames it over `path`.
// The folder must exist. On failure removes the temporary file, sets `error` (if not null) to
// one line naming the path and returns false. Never throws.
bool write_file_atomically(const std::filesystem::path& path, std::string_view bytes,
                           std::string* error);

}  // namespace rigc
