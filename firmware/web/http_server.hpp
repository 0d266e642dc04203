// The commissioning page's HTTP server: libmicrohttpd driven by a thread of its own at a lower
// priority (nice kServerNice), with bounded connections, per-address connections, header memory,
// body size and idle time (web_limits.hpp). It parses HTTP; what a request means is the
// handler's (web_app.hpp).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <thread>

#include "recog/base/status.hpp"

struct MHD_Daemon;
struct MHD_Connection;

namespace sh::fw::web {

struct HttpRequest {
  const char* method = "";  // "GET", "POST", ...
  const char* path = "";    // without the query
  const char* body = "";    // NUL-terminated; body_bytes without the NUL
  size_t body_bytes = 0;
  // A header or query argument of the request, or nullptr.
  const char* Header(const char* name) const;
  const char* Argument(const char* name) const;
  // The value of a cookie, or an empty string.
  std::string Cookie(const char* name) const;
  MHD_Connection* connection = nullptr;
};

struct HttpResponse {
  int status = 200;
  const char* content_type = "text/plain; charset=utf-8";
  std::string body;
  // Served in place of `body` (data linked into the program).
  const void* static_data = nullptr;
  size_t static_bytes = 0;
  std::string set_cookie;           // a Set-Cookie header, if not empty
  std::string content_disposition;  // "attachment; filename=..." for downloads
  bool cache = false;               // false: Cache-Control: no-store
};

class HttpHandler {
 public:
  virtual ~HttpHandler() = default;
  // Called on the server thread, one request at a time.
  virtual void Handle(const HttpRequest& request, HttpResponse* response) = 0;
};

struct HttpServerConfig {
  const char* bind_address = "127.0.0.1";  // IPv4 or IPv6
  uint16_t port = 0;                       // 0 = ephemeral
  // HTTPS only when both are given: PEM text of the certificate (chain) and its private key,
  // valid until Stop().
  const char* tls_cert_pem = nullptr;
  const char* tls_key_pem = nullptr;
};

class HttpServer {
 public:
  HttpServer() = default;
  ~HttpServer() { Stop(); }
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  // Binds and starts the server thread. Errors name the address and port.
  Status Start(const HttpServerConfig& config, HttpHandler* handler);
  void Stop();
  uint16_t port() const { return port_; }
  bool https() const { return https_; }

  // Requests refused by the server itself (body too large), for the page's counters.
  uint64_t refused() const { return refused_.load(); }

 private:
  friend struct HttpServerCallbacks;  // libmicrohttpd's callbacks (http_server.cpp)
  void Loop();

  MHD_Daemon* daemon_ = nullptr;
  bool https_ = false;
  HttpHandler* handler_ = nullptr;
  uint16_t port_ = 0;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> refused_{0};
  size_t large_bytes_ = 0;  // of large answers not yet sent (server thread)
  std::thread thread_;
};

}  // namespace sh::fw::web
