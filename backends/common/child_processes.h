// Programs that rigc starts (POV-Ray, Blender, COLMAP) stop when rigc is stopped.
#pragma once

#include <sys/types.h>

namespace rigc::backends {

// While a child is watched, a SIGINT, SIGTERM or SIGHUP that stops rigc sends the child a
// SIGTERM first. A signal sent to rigc alone (`kill`, `timeout`, a closed ssh session) left
// POV-Ray rendering on its own, into the folder a rerun then rendered into as well. (A SIGKILL
// cannot be caught: its children still run on; nor can a signal in the microseconds between
// the spawn and the watch.)
void watch_child(pid_t pid);
void unwatch_child(pid_t pid);

// Unwatches on scope exit, or at release(): call that as soon as the child is reaped, so that
// a signal cannot reach another process that is given its pid.
class WatchedChild {
 public:
  explicit WatchedChild(pid_t pid) : pid_(pid) { watch_child(pid_); }
  ~WatchedChild() { release(); }
  void release() {
    if (pid_ > 0) unwatch_child(pid_);
    pid_ = 0;
  }
  WatchedChild(const WatchedChild&) = delete;
  WatchedChild& operator=(const WatchedChild&) = delete;

 private:
  pid_t pid_;
};

}  // namespace rigc::backends
