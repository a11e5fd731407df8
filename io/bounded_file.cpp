#include "io/bounded_file.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <system_error>

#include "io/file_status.h"

namespace rigc {

namespace fs = std::filesystem;

namespace {

// Closes a descriptor when it goes out of scope.
struct Descriptor {
  int fd;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

std::string system_reason() {
  return std::generic_category().message(errno);
}

}  // namespace

std::string size_in_words(std::size_t bytes) {
  if (bytes >= (1u << 20) && bytes % (1u << 20) == 0) return fmt::format("{} MB", bytes >> 20);
  if (bytes >= (1u << 10) && bytes % (1u << 10) == 0) return fmt::format("{} KB", bytes >> 10);
  return fmt::format("{} bytes", bytes);
}

std::optional<BoundedFile> read_bounded_file(const fs::path& path, std::size_t most_bytes,
                                             std::string* why) {
  if (std::string reason = why_not_readable(path); !reason.empty()) {
    *why = std::move(reason);
    return std::nullopt;
  }
  // O_NONBLOCK: if a pipe took the file's place since the check, open returns instead of waiting
  // for a writer; fstat below then refuses it.
  const Descriptor file{::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK)};
  if (file.fd < 0) {
    *why = "cannot be opened: " + system_reason();
    return std::nullopt;
  }
  struct stat status {};
  if (::fstat(file.fd, &status) != 0 || !S_ISREG(status.st_mode)) {
    *why = "is not a regular file (a device, a pipe or a socket)";
    return std::nullopt;
  }
  const auto too_large = [&] {
    *why = fmt::format("is larger than {}", size_in_words(most_bytes));
    return std::nullopt;
  };
  if (static_cast<std::uintmax_t>(status.st_size) > most_bytes) return too_large();
  BoundedFile result;
  result.identity = {status.st_dev, status.st_ino};
  result.bytes.reserve(static_cast<std::size_t>(status.st_size));
  // A file that grows while it is read is read up to the bound and one chunk more.
  std::array<char, 1 << 16> chunk;
  for (;;) {
    const ssize_t n = ::read(file.fd, chunk.data(), chunk.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      *why = "cannot be read: " + system_reason();
      return std::nullopt;
    }
    if (n == 0) break;
    result.bytes.append(chunk.data(), static_cast<std::size_t>(n));
    if (result.bytes.size() > most_bytes) return too_large();
  }
  return result;
}

std::optional<FileIdentity> identity_of(const fs::path& path) {
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0) return std::nullopt;
  return FileIdentity{status.st_dev, status.st_ino};
}

}  // namespace rigc
