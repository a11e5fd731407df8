#include "studio/deadline_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>

namespace rigc::studio {

namespace {

using Clock = std::chrono::steady_clock;

// Waits until `sock` is ready for `events`, at most `ms` milliseconds.
bool ready(socket_t sock, short events, long ms) {
  pollfd p{sock, events, 0};
  for (;;) {
    const int n = ::poll(&p, 1, static_cast<int>(std::max(0L, ms)));
    if (n < 0 && errno == EINTR) continue;
    return n > 0;
  }
}

void address_of(socket_t sock, bool remote, std::string& ip, int& port) {
  sockaddr_storage address{};
  socklen_t length = sizeof address;
  const int rc = remote ? ::getpeername(sock, reinterpret_cast<sockaddr*>(&address), &length)
                        : ::getsockname(sock, reinterpret_cast<sockaddr*>(&address), &length);
  if (rc != 0) return;
  std::array<char, INET6_ADDRSTRLEN> text{};
  if (address.ss_family == AF_INET) {
    const auto& a = reinterpret_cast<const sockaddr_in&>(address);
    ::inet_ntop(AF_INET, &a.sin_addr, text.data(), text.size());
    port = ntohs(a.sin_port);
  } else if (address.ss_family == AF_INET6) {
    const auto& a = reinterpret_cast<const sockaddr_in6&>(address);
    ::inet_ntop(AF_INET6, &a.sin6_addr, text.data(), text.size());
    port = ntohs(a.sin6_port);
  }
  ip = text.data();
}

// A connection's socket as httplib's Stream: reads buffered and bounded by the current request's
// deadline, writes bounded by the write timeout.
class DeadlineStream final : public httplib::Stream {
 public:
  DeadlineStream(socket_t sock, long write_timeout_ms)
      : sock_(sock), write_timeout_ms_(write_timeout_ms) {}

  void start_request(std::chrono::milliseconds deadline) { deadline_ = Clock::now() + deadline; }
  bool has_buffered() const { return begin_ < end_; }

  bool is_readable() const override {
    return has_buffered() || ready(sock_, POLLIN, remaining_ms());
  }
  bool is_writable() const override { return ready(sock_, POLLOUT, write_timeout_ms_); }

  ssize_t read(char* ptr, size_t size) override {
    if (!has_buffered()) {
      if (!ready(sock_, POLLIN, remaining_ms())) return -1;
      ssize_t n;
      do {
        n = ::recv(sock_, buffer_.data(), buffer_.size(), 0);
      } while (n < 0 && errno == EINTR);
      if (n <= 0) return n;
      begin_ = 0;
      end_ = static_cast<size_t>(n);
    }
    const size_t n = std::min(size, end_ - begin_);
    std::copy_n(buffer_.data() + begin_, n, ptr);
    begin_ += n;
    return static_cast<ssize_t>(n);
  }

  ssize_t write(const char* ptr, size_t size) override {
    if (!is_writable()) return -1;
    ssize_t n;
    do {
      n = ::send(sock_, ptr, size, MSG_NOSIGNAL);
    } while (n < 0 && errno == EINTR);
    return n;
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    address_of(sock_, true, ip, port);
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    address_of(sock_, false, ip, port);
  }
  socket_t socket() const override { return sock_; }

 private:
  long remaining_ms() const {
    return std::chrono::duration_cast<std::chrono::milliseconds>(deadline_ - Clock::now()).count();
  }

  socket_t sock_;
  long write_timeout_ms_;
  Clock::time_point deadline_ = Clock::now();
  std::array<char, 4096> buffer_{};
  size_t begin_ = 0, end_ = 0;
};

}  // namespace

DeadlineServer::DeadlineServer(std::chrono::milliseconds request_deadline, int workers)
    : request_deadline_(request_deadline) {
  new_task_queue = [workers] { return new httplib::ThreadPool(static_cast<size_t>(workers)); };
}

bool DeadlineServer::wait_for_request(socket_t sock) const {
  // In steps, so that a stopped server's connections end within one.
  constexpr long kStepMs = 100;
  const auto until = Clock::now() + std::chrono::seconds(keep_alive_timeout_sec_);
  while (svr_sock_ != INVALID_SOCKET && Clock::now() < until) {
    if (ready(sock, POLLIN, kStepMs)) return true;
  }
  return false;
}

bool DeadlineServer::process_and_close_socket(socket_t sock) {
  DeadlineStream stream(sock,
                        static_cast<long>(write_timeout_sec_ * 1000 + write_timeout_usec_ / 1000));
  bool ok = false;
  for (size_t left = keep_alive_max_count_; left > 0 && svr_sock_ != INVALID_SOCKET; --left) {
    if (!stream.has_buffered() && !wait_for_request(sock)) break;
    stream.start_request(request_deadline_);
    bool closed = false;
    ok = process_request(stream, left == 1, closed, nullptr);
    if (!ok || closed) break;
  }
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
  return ok;
}

}  // namespace rigc::studio
