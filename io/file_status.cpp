#include "io/file_status.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

namespace rigc {

namespace fs = std::filesystem;

std::string why_not_readable(const fs::path& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec == std::errc::too_many_symbolic_link_levels) return "is a loop of symbolic links";
  if (ec && ec != std::errc::no_such_file_or_directory) return "cannot be read: " + ec.message();
  if (!fs::exists(status)) {
    return fs::is_symlink(fs::symlink_status(path, ec)) ? "is a symbolic link to nothing"
                                                        : "does not exist";
  }
  if (fs::is_directory(status)) return "is a folder";
  if (!fs::is_regular_file(status)) return "is not a regular file (a device, a pipe or a socket)";
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return "cannot be opened: " + std::generic_category().message(errno);
  ::close(fd);
  return "";
}

bool names_nothing(const fs::path& path) {
  std::error_code ec;
  return !fs::exists(fs::symlink_status(path, ec));
}

}  // namespace rigc
