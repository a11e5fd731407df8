#include "studio/server.h"

#include <arpa/inet.h>
#include <fmt/format.h>
#include <httplib.h>
#include <ifaddrs.h>
#include <netinet/in.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>

#include "studio/deadline_server.h"
#include "studio/edit_requests.h"
#include "studio/page_files.h"

namespace rigc::studio {
namespace {

// Debian's libjs-three: three.js r111 and the two examples the page uses.
constexpr const char* kThreeDir = "/usr/share/javascript/three/";

// Content types with their charset, which Debian's cpp-httplib (0.11) leaves uncompressed: it
// compresses the bare types with Brotli at quality 11, about a second for a coverage's
// megabyte of JSON, and compression gains nothing on the loopback the studio serves.
constexpr const char* kJson = "application/json; charset=utf-8";
constexpr const char* kJavaScript = "application/javascript; charset=utf-8";

void send_error(httplib::Response& res, int status, const std::string& message) {
  res.status = status;
  res.set_content(answer_text(nlohmann::json{{"error", message}}), kJson);
}

void send_json(httplib::Response& res, const nlohmann::json& body) {
  res.set_content(answer_text(body), kJson);
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Timing-safe comparison of the token.
bool same_token(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

// localhost, the host's name, and the addresses of its interfaces (IPv6 in brackets), as a Host
// header names them.
std::vector<std::string> machine_names() {
  std::vector<std::string> names = {"127.0.0.1", "localhost", "[::1]"};
  char hostname[256] = {};
  if (gethostname(hostname, sizeof hostname - 1) == 0 && hostname[0] != 0) {
    names.push_back(hostname);
  }
  ifaddrs* interfaces = nullptr;
  if (getifaddrs(&interfaces) != 0) return names;
  for (const ifaddrs* i = interfaces; i; i = i->ifa_next) {
    if (!i->ifa_addr) continue;
    char text[INET6_ADDRSTRLEN] = {};
    const int family = i->ifa_addr->sa_family;
    if (family == AF_INET) {
      inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in*>(i->ifa_addr)->sin_addr, text,
                sizeof text);
      names.push_back(text);
    } else if (family == AF_INET6) {
      inet_ntop(AF_INET6, &reinterpret_cast<const sockaddr_in6*>(i->ifa_addr)->sin6_addr, text,
                sizeof text);
      names.push_back("[" + std::string(text) + "]");
    }
  }
  freeifaddrs(interfaces);
  return names;
}

}  // namespace

std::string random_token() {
  std::random_device device;
  std::string token;
  for (int i = 0; i < 4; ++i) token += fmt::format("{:08x}", device());
  return token;
}

StudioServer::StudioServer(Session& session, ServerOptions options)
    : session_(session),
      options_(std::move(options)),
      server_(new DeadlineServer(options_.request_deadline, options_.workers)) {
  if (options_.token.empty()) options_.token = random_token();
  server_->set_payload_max_length(1 << 20);
  server_->set_tcp_nodelay(true);
  add_routes();
}

StudioServer::~StudioServer() = default;

int StudioServer::bind(std::string* error) {
  port_ = options_.port == 0
              ? server_->bind_to_any_port(options_.host)
              : (server_->bind_to_port(options_.host, options_.port) ? options_.port : -1);
  if (port_ < 0) *error = fmt::format("cannot listen on {}:{}", options_.host, options_.port);
  return port_;
}

bool StudioServer::run() {
  return server_->listen_after_bind();
}
void StudioServer::stop() {
  server_->stop();
}
bool StudioServer::is_running() const {
  return server_->is_running();
}

std::string StudioServer::url() const {
  std::string host = options_.host;
  if (host == "0.0.0.0" || host == "::") {
    // Every interface: the machine's name, which the Host check accepts.
    char hostname[256] = {};
    host = gethostname(hostname, sizeof hostname - 1) == 0 && hostname[0] ? hostname : "localhost";
  }
  const bool v6 = host.find(':') != std::string::npos;
  return fmt::format("http://{}{}{}:{}/?token={}", v6 ? "[" : "", host, v6 ? "]" : "", port_,
                     options_.token);
}

// The names this server answers to: its own address, and localhost's when it listens there; on
// every interface (0.0.0.0, ::), the machine's name and each of its addresses too.
bool StudioServer::allowed_host(const std::string& host) const {
  const std::string port = ":" + std::to_string(port_);
  std::vector<std::string> names = {options_.host};
  if (options_.host == "127.0.0.1" || options_.host == "localhost" || options_.host == "::1") {
    names = {"127.0.0.1", "localhost", "[::1]"};
  } else if (options_.host == "0.0.0.0" || options_.host == "::") {
    names = machine_names();
  } else if (options_.host.find(':') != std::string::npos) {
    names = {"[" + options_.host + "]"};
  }
  for (const auto& name : names) {
    if (host == name + port) return true;
  }
  return false;
}

void StudioServer::add_routes() {
  server_->set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    if (!allowed_host(req.get_header_value("Host"))) {
      send_error(res, 403, "this server answers only to its own address (Host header)");
      return httplib::Server::HandlerResponse::Handled;
    }
    const std::string origin = req.get_header_value("Origin");
    if (!origin.empty() && (origin.rfind("http://", 0) != 0 || !allowed_host(origin.substr(7)))) {
      send_error(res, 403, "requests from other sites are refused (Origin header)");
      return httplib::Server::HandlerResponse::Handled;
    }
    const std::string token = req.has_param("token") ? req.get_param_value("token")
                                                     : req.get_header_value("X-Rigc-Token");
    if (!same_token(token, options_.token)) {
      send_error(res, 403, "a valid token is required: open the address `rigc studio` printed");
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  server_->set_exception_handler(
      [](const httplib::Request&, httplib::Response& res, std::exception_ptr error) {
        std::string message = "internal error";
        try {
          std::rethrow_exception(error);
        } catch (const std::exception& e) {
          message = std::string("internal error: ") + e.what();
        } catch (...) {
        }
        send_error(res, 500, message);
      });
  server_->set_error_handler([](const httplib::Request&, httplib::Response& res) {
    if (res.body.empty()) send_error(res, res.status, "no such request");
  });
  add_page_routes();
  add_edit_routes();
}

void StudioServer::add_page_routes() {
  auto serve = [this](const char* route, std::string_view body, const char* type) {
    server_->Get(route, [body, type](const httplib::Request&, httplib::Response& res) {
      res.set_content(std::string(body), type);
      res.set_header("Cache-Control", "no-store");
    });
  };
  server_->Get("/", [this](const httplib::Request&, httplib::Response& res) {
    std::string html(page::k_index_html);
    for (size_t at; (at = html.find("@TOKEN@")) != std::string::npos;) {
      html.replace(at, 7, options_.token);
    }
    res.set_content(html, "text/html; charset=utf-8");
    res.set_header("Cache-Control", "no-store");
  });
  for (const page::Module& module : page::kModules) {
    server_->Get("/" + std::string(module.name),
                 [text = module.text](const httplib::Request&, httplib::Response& res) {
                   res.set_content(std::string(text), kJavaScript);
                   res.set_header("Cache-Control", "no-store");
                 });
  }
  serve("/studio.css", page::k_studio_css, "text/css");
  auto three = [this](const char* route, std::string file) {
    server_->Get(route, [file](const httplib::Request&, httplib::Response& res) {
      const std::string body = read_file(kThreeDir + file);
      if (body.empty()) {
        return send_error(res, 404, "install libjs-three (Debian) for the 3D coverage view");
      }
      res.set_content(body, kJavaScript);
    });
  };
  three("/three/three.min.js", "build/three.min.js");
  three("/three/OrbitControls.js", "examples/js/controls/OrbitControls.js");

  server_->Get("/api/state", [this](const httplib::Request&, httplib::Response& res) {
    session_.reload_if_changed();
    send_json(res, session_.state());
  });
  server_->Get("/api/frame", [this](const httplib::Request& req, httplib::Response& res) {
    const int full_width = session_.sensor_width_px();
    double width = 1280;
    if (req.has_param("width")) {
      width = std::strtod(req.get_param_value("width").c_str(), nullptr);
      if (!(width >= 64 && width <= 4096)) {
        return send_error(res, 400, "width must be 64..4096 pixels");
      }
    }
    const std::string draft = req.has_param("draft") ? req.get_param_value("draft") : "0";
    if (draft != "0" && draft != "1") return send_error(res, 400, "draft must be 0 or 1");
    std::string error;
    const auto frame = session_.frame(std::min(1.0, width / full_width), draft == "1", &error);
    if (!frame) return send_error(res, 500, error);
    std::string bins;
    for (const int count : frame->histogram.bins)
      bins += (bins.empty() ? "" : ",") + std::to_string(count);
    res.set_header("X-Rigc-Histogram", bins);
    res.set_header("X-Rigc-Clipped", fmt::format("{:.5f}", frame->histogram.clipped));
    res.set_header("X-Rigc-Mean", fmt::format("{:.3f}", frame->histogram.mean_luma));
    res.set_header("X-Rigc-Render-Ms", fmt::format("{:.1f}", frame->render_ms));
    std::string stages;
    for (const auto& [stage, ms] : frame->stage_ms) {
      stages += fmt::format("{}{}={:.1f}", stages.empty() ? "" : ",", stage, ms);
    }
    res.set_header("X-Rigc-Stages", stages);
    res.set_header("X-Rigc-Encode-Ms", fmt::format("{:.1f}", frame->encode_ms));
    res.set_header("X-Rigc-Reused-Render", frame->reused_render ? "1" : "0");
    res.set_header("Cache-Control", "no-store");
    res.set_content(frame->jpeg, "image/jpeg");
  });
  // 409 when the scene changed during the analysis: the page asks again for the new one.
  auto analysis = [this](const char* route, std::optional<nlohmann::json> (Session::*method)()) {
    server_->Get(route, [this, method](const httplib::Request&, httplib::Response& res) {
      const auto result = (session_.*method)();
      if (!result) return send_error(res, 409, "the scene changed during the analysis");
      send_json(res, *result);
    });
  };
  // ?capture=1: the page waits for it after a capture; it goes before background analyses.
  server_->Get("/api/coverage", [this](const httplib::Request& req, httplib::Response& res) {
    const auto result = session_.coverage(req.get_param_value("capture") != "1");
    if (!result) return send_error(res, 409, "the scene changed during the analysis");
    send_json(res, *result);
  });
  analysis("/api/advice", &Session::advice);
  server_->Get("/api/mesh", [this](const httplib::Request&, httplib::Response& res) {
    send_json(res, session_.mesh());
  });
}

void StudioServer::add_edit_routes() {
  for (const std::string_view route : edit_routes()) {
    server_->Post(std::string(route),
                  [this, route](const httplib::Request& req, httplib::Response& res) {
                    const EditAnswer answer = answer_edit(session_, route, req.body);
                    res.status = answer.status;
                    res.set_content(answer_text(answer.body), kJson);
                  });
  }
  add_reference_routes();
}

// The reference check (started through edit_routes): its status, cancel, and the two images.
void StudioServer::add_reference_routes() {
  server_->Get("/api/reference", [this](const httplib::Request&, httplib::Response& res) {
    send_json(res, session_.reference().status());
  });
  server_->Post("/api/reference/cancel", [this](const httplib::Request&, httplib::Response& res) {
    session_.reference().cancel();
    send_json(res, {{"ok", true}});
  });
  server_->Get("/api/reference/image", [this](const httplib::Request& req, httplib::Response& res) {
    const std::string which = req.has_param("which") ? req.get_param_value("which") : "reference";
    if (which != "reference" && which != "preview") {
      return send_error(res, 400, "which is reference or preview");
    }
    const std::string jpeg = session_.reference().image(which);
    if (jpeg.empty()) return send_error(res, 404, "no reference check has finished yet");
    res.set_header("Cache-Control", "no-store");
    res.set_content(jpeg, "image/jpeg");
  });
}

}  // namespace rigc::studio
