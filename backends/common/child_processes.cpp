#include "backends/common/child_processes.h"

#include <signal.h>

#include <array>
#include <atomic>
#include <mutex>

namespace rigc::backends {
namespace {

// Lock-free slots, read by the signal handler (0: free). A few children run at once at most.
std::array<std::atomic<pid_t>, 16> g_children{};
static_assert(std::atomic<pid_t>::is_always_lock_free, "the signal handler reads the slots");

constexpr std::array kStopSignals = {SIGINT, SIGTERM, SIGHUP};

// Async-signal-safe: atomics, kill, signal and raise only.
void stop_children_and_die(int signal_number) {
  for (auto& child : g_children) {
    const pid_t pid = child.load();
    if (pid > 0) kill(pid, SIGTERM);
  }
  signal(signal_number, SIG_DFL);
  raise(signal_number);
}

void install_handlers() {
  for (const int signal_number : kStopSignals) {
    struct sigaction previous {};
    sigaction(signal_number, nullptr, &previous);
    // A signal the caller ignores (nohup's SIGHUP) stays ignored; a handler of its own stays.
    if (previous.sa_handler != SIG_DFL) continue;
    struct sigaction action {};
    action.sa_handler = stop_children_and_die;
    sigemptyset(&action.sa_mask);
    sigaction(signal_number, &action, nullptr);
  }
}

}  // namespace

void watch_child(pid_t pid) {
  static std::once_flag installed;
  std::call_once(installed, install_handlers);
  for (auto& child : g_children) {
    pid_t expected = 0;
    if (child.compare_exchange_strong(expected, pid)) return;
  }
}

void unwatch_child(pid_t pid) {
  for (auto& child : g_children) {
    pid_t expected = pid;
    if (child.compare_exchange_strong(expected, 0)) return;
  }
}

}  // namespace rigc::backends
