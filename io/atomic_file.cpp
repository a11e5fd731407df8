#include "io/atomic_file.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <system_error>

#include "io/input_files.h"

namespace rigc {
namespace {

std::string errno_text(int code) {
  return std::system_category().message(code);
}

void set_error(std::string* error, std::string text) {
  if (error != nullptr) *error = std::move(text);
}

// A suffix no other writer (thread or process) uses at the same time.
std::string unique_suffix() {
  static std::atomic<std::uint64_t> counter{0};
  const auto ticks = std::chrono::steady_clock::now().time_since_epoch().count();
  return fmt::format(".tmp.{}.{}.{:x}", static_cast<long>(::getpid()), counter.fetch_add(1),
                     static_cast<std::uint64_t>(ticks) & 0xffffff);
}

bool write_all(int fd, std::string_view bytes) {
  const char* data = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace

std::filesystem::path temporary_path_beside(const std::filesystem::path& path) {
  return path.parent_path() / ("." + path.filename().string() + unique_suffix());
}

std::filesystem::path file_to_replace(const std::filesystem::path& path, std::string* error) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path target = path;
  // Follows a chain of links by hand: weakly_canonical takes a link to a missing file for a
  // missing file of its own name, and the write replaced the link.
  for (int links = 0; fs::is_symlink(fs::symlink_status(target, ec)); ++links) {
    const fs::path to = fs::read_symlink(target, ec);
    if (ec || links == 40) {
      set_error(error,
                fmt::format("cannot write {}: the symbolic link leads nowhere: {}", path.string(),
                            ec ? ec.message() : "Too many levels of symbolic links"));
      return {};
    }
    target = to.is_absolute() ? to : target.parent_path() / to;
  }
  if (target != path) {
    std::error_code folder_ec;
    const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    if (!fs::is_directory(folder, folder_ec)) {
      set_error(error, fmt::format("cannot write {}: it is a symbolic link to '{}', whose folder "
                                   "does not exist",
                                   path.string(), target.string()));
      return {};
    }
  }
  if (const auto input = protected_input_at(target)) {
    set_error(error, fmt::format("cannot write {}: it is {}, an input of this command; choose "
                                 "another name or folder",
                                 path.string(), *input));
    return {};
  }
  const fs::file_status status = fs::status(target, ec);
  if (fs::exists(status) && !fs::is_regular_file(status)) {
    set_error(error, fmt::format("cannot write {}: it is not a regular file (a folder, a device "
                                 "or a pipe); name a file",
                                 path.string()));
    return {};
  }
  return target;
}

bool write_atomically(const std::filesystem::path& requested, const FileWriter& write,
                      std::string* error) {
  std::filesystem::path temporary;
  try {
    if (requested.filename().empty()) {
      set_error(error, fmt::format("cannot write '{}': not a file name", requested.string()));
      return false;
    }
    const std::filesystem::path path = file_to_replace(requested, error);
    if (path.empty()) return false;
    temporary = temporary_path_beside(path);
    std::string reason;
    bool written = write(temporary, &reason);
    if (written && std::rename(temporary.c_str(), path.c_str()) != 0) {
      reason = errno_text(errno);
      written = false;
    }
    if (written) return true;
    ::unlink(temporary.c_str());
    set_error(error, fmt::format("cannot write {}: {}", path.string(),
                                 reason.empty() ? "the writer failed" : reason));
    return false;
  } catch (const std::exception& e) {
    if (!temporary.empty()) ::unlink(temporary.c_str());
    set_error(error, fmt::format("cannot write {}: {}", requested.string(), e.what()));
    return false;
  }
}

bool write_file_atomically(const std::filesystem::path& path, std::string_view bytes,
                           std::string* error) {
  return write_atomically(
      path,
      [bytes](const std::filesystem::path& temporary, std::string* reason) {
        const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0) {
          *reason = errno_text(errno);
          return false;
        }
        const bool written = write_all(fd, bytes);
        int code = written ? 0 : errno;
        if (::close(fd) != 0 && code == 0) code = errno;
        if (code != 0) *reason = errno_text(code);
        return code == 0;
      },
      error);
}

}  // namespace rigc
