// Files from outside read whole, with bounds: the scene, a sweep file, other tools' camera files.
// Regular files only, opened without blocking (a pipe put where a file was is refused, not waited
// on), and never more than a stated size, so that /dev/zero or a 150 MB "scene" costs nothing.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

namespace rigc {

// Other tools' camera files and sparse models (COLMAP, Bundler, Meshroom, Middlebury): a model of
// many thousand photos, its 2D points included, stays well under this. (The scene's own bound is
// compiler/limits.h's kMostSceneFileBytes.)
inline constexpr std::size_t kMostCameraFileBytes = std::size_t{512} << 20;

// Which file a path led to when it was read (symbolic links followed): a writer compares it with
// the file there now before it replaces what it read.
struct FileIdentity {
  dev_t device = 0;
  ino_t inode = 0;
  bool operator==(const FileIdentity&) const = default;
};

struct BoundedFile {
  std::string bytes;
  FileIdentity identity;
};

// The whole regular file at `path`, at most `most_bytes`. Nullopt with `why` worded to follow the
// file's name, as why_not_readable words it ("is a folder", "is not a regular file (a device, a
// pipe or a socket)", ...), or "is larger than 16 MB".
std::optional<BoundedFile> read_bounded_file(const std::filesystem::path& path,
                                             std::size_t most_bytes, std::string* why);

// The identity of the file at `path` now (symbolic links followed); nullopt when there is none.
std::optional<FileIdentity> identity_of(const std::filesystem::path& path);

// "16 MB", "64 KB", "200 bytes": a bound in words.
std::string size_in_words(std::size_t bytes);

}  // namespace rigc
