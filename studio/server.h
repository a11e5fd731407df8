// The studio's HTTP server (cpp-httplib): the page, three.js from Debian's libjs-three, and the
// JSON API over one Session. Every request needs the session's token (`?token=` or the header
// X-Rigc-Token); a Host or Origin header naming another host is refused (DNS rebinding).
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "studio/session.h"

namespace httplib {
class Server;
}

namespace rigc::studio {

struct ServerOptions {
  std::string host = "127.0.0.1";
  int port = 0;       // 0: any free port
  std::string token;  // empty: a random one
  // A request (line, headers and body) must arrive within this; connections are served by
  // `workers` threads.
  std::chrono::milliseconds request_deadline{10000};
  int workers = 32;
};

// 32 hex digits from the system's random source.
std::string random_token();

class StudioServer {
 public:
  StudioServer(Session& session, ServerOptions options);
  ~StudioServer();

  // Binds the socket; the port, or -1 with `error` set.
  int bind(std::string* error);
  // Serves until stop() (from any thread). False when it could not serve.
  bool run();
  void stop();
  bool is_running() const;

  const std::string& token() const { return options_.token; }
  int port() const { return port_; }
  // The address to open, with the token.
  std::string url() const;

 private:
  void add_routes();
  void add_page_routes();
  void add_edit_routes();
  void add_reference_routes();
  bool allowed_host(const std::string& host_header) const;

  Session& session_;
  ServerOptions options_;
  int port_ = -1;
  std::unique_ptr<httplib::Server> server_;
};

}  // namespace rigc::studio
