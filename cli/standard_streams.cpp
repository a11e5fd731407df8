#include "cli/standard_streams.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <iostream>
#include <system_error>

#include "cli/commands.h"

namespace rigc::cli {

void guard_standard_streams() {
  for (const int fd : {STDIN_FILENO, STDOUT_FILENO, STDERR_FILENO}) {
    if (::fcntl(fd, F_GETFD) != -1 || errno != EBADF) continue;
    const int opened = ::open("/dev/null", fd == STDERR_FILENO ? O_WRONLY : O_RDONLY);
    if (opened >= 0 && opened != fd) {
      ::dup2(opened, fd);
      ::close(opened);
    }
  }
  ::signal(SIGXFSZ, SIG_IGN);
}

int finish_standard_output(int code) {
  std::cout.flush();
  errno = 0;
  const bool flushed = std::fflush(stdout) == 0;
  int reason = errno;
  if (flushed && std::cout && !std::ferror(stdout)) return code;
  // The write that failed was earlier, its errno gone: an empty write asks again (a device
  // that is full or a descriptor not open for writing says so; a file on a full disk may not).
  if (reason == 0 && ::write(STDOUT_FILENO, "", 0) < 0) reason = errno;
  std::cerr << fmt::format(
      "rigc: error: cannot write to standard output: {}\n",
      reason != 0 ? std::system_category().message(reason) : "the output is incomplete");
  return code != kExitOk ? code : kExitInternalError;
}

}  // namespace rigc::cli
