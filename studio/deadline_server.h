// An httplib server that reads each request against a deadline. httplib's read timeout is per
// recv: a client sending a header byte every two seconds held a worker thread forever, and eight
// of them stalled the studio. Here the request line, headers and body must all arrive within
// `request_deadline` of the connection's turn to send one; a late request's connection is closed.
#pragma once

#include <httplib.h>

#include <chrono>

namespace rigc::studio {

class DeadlineServer : public httplib::Server {
 public:
  // `workers` threads serve connections (httplib's default is 8 on a 2-core machine).
  DeadlineServer(std::chrono::milliseconds request_deadline, int workers);

 private:
  bool process_and_close_socket(socket_t sock) override;
  // Waits for the next request of a kept-alive connection: false when none comes within the
  // keep-alive timeout or the server stops.
  bool wait_for_request(socket_t sock) const;

  std::chrono::milliseconds request_deadline_;
};

}  // namespace rigc::studio
