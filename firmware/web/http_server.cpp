#include "firmware/web/http_server.hpp"

#include <arpa/inet.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <memory>

#include "firmware/web/web_limits.hpp"

namespace sh::fw::web {

const char* HttpRequest::Header(const char* name) const {
  return MHD_lookup_connection_value(connection, MHD_HEADER_KIND, name);
}

const char* HttpRequest::Argument(const char* name) const {
  return MHD_lookup_connection_value(connection, MHD_GET_ARGUMENT_KIND, name);
}

std::string HttpRequest::Cookie(const char* name) const {
  const char* value = MHD_lookup_connection_value(connection, MHD_COOKIE_KIND, name);
  return value != nullptr ? std::string(value) : std::string();
}

// What one request has sent so far: its body, bounded by kMaxBodyBytes.
struct RequestState {
  std::string body;
  bool too_large = false;
};

// A large answer's bytes, counted against kMaxLargeResponseBytes until libmicrohttpd frees them.
struct LargeBody {
  HttpServer* server;
  size_t bytes;
  std::unique_ptr<char[]> data;
};

struct HttpServerCallbacks {
  static void FreeLarge(void* cls) {
    auto* body = static_cast<LargeBody*>(cls);
    body->server->large_bytes_ -= body->bytes;
    delete body;
  }

  static MHD_Response* Create(HttpServer* server, const HttpResponse& r) {
    if (r.static_data != nullptr) {
      return MHD_create_response_from_buffer(r.static_bytes, const_cast<void*>(r.static_data),
                                             MHD_RESPMEM_PERSISTENT);
    }
    if (r.body.size() <= kLargeResponseBytes) {
      return MHD_create_response_from_buffer(r.body.size(), const_cast<char*>(r.body.data()),
                                             MHD_RESPMEM_MUST_COPY);
    }
    if (server->large_bytes_ + r.body.size() > kMaxLargeResponseBytes) return nullptr;
    auto* body = new LargeBody{server, r.body.size(), std::make_unique<char[]>(r.body.size())};
    std::memcpy(body->data.get(), r.body.data(), r.body.size());
    server->large_bytes_ += body->bytes;
    return MHD_create_response_from_buffer_with_free_callback_cls(body->bytes, body->data.get(),
                                                                  &FreeLarge, body);
  }

  static MHD_Result Queue(HttpServer* server, MHD_Connection* connection, const HttpResponse& r) {
    MHD_Response* response = Create(server, r);
    if (response == nullptr) {
      if (r.body.size() <= kLargeResponseBytes) return MHD_NO;
      HttpResponse busy;  // other downloads hold the memory for large answers
      busy.status = MHD_HTTP_SERVICE_UNAVAILABLE;
      busy.body = "busy with other downloads: try again\n";
      return Queue(server, connection, busy);
    }
    MHD_add_response_header(response, MHD_HTTP_HEADER_CONTENT_TYPE, r.content_type);
    MHD_add_response_header(response, MHD_HTTP_HEADER_CACHE_CONTROL,
                            r.cache ? "max-age=300" : "no-store");
    // The page loads nothing from elsewhere and is never framed by another site.
    MHD_add_response_header(
        response, "Content-Security-Policy",
        "default-src 'self'; img-src 'self' blob: data:; frame-ancestors 'none'");
    MHD_add_response_header(response, "X-Content-Type-Options", "nosniff");
    MHD_add_response_header(response, "X-Frame-Options", "DENY");
    MHD_add_response_header(response, "Referrer-Policy", "no-referrer");
    if (!r.set_cookie.empty()) {
      MHD_add_response_header(response, MHD_HTTP_HEADER_SET_COOKIE, r.set_cookie.c_str());
    }
    if (!r.content_disposition.empty()) {
      MHD_add_response_header(response, MHD_HTTP_HEADER_CONTENT_DISPOSITION,
                              r.content_disposition.c_str());
    }
    const MHD_Result queued =
        MHD_queue_response(connection, static_cast<unsigned>(r.status), response);
    MHD_destroy_response(response);
    return queued;
  }

  static MHD_Result Refuse(HttpServer* server, MHD_Connection* connection, int status,
                           const char* text) {
    ++server->refused_;
    HttpResponse r;
    r.status = status;
    r.body = text;
    return Queue(server, connection, r);
  }

  static MHD_Result Dispatch(void* cls, MHD_Connection* connection, const char* url,
                             const char* method, const char* version, const char* upload_data,
                             size_t* upload_data_size, void** request_state) {
    auto* server = static_cast<HttpServer*>(cls);
    auto* state = static_cast<RequestState*>(*request_state);
    if (state == nullptr) {
      // A declared body over the limit is refused before it is read.
      const char* length =
          MHD_lookup_connection_value(connection, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_LENGTH);
      if (length != nullptr && std::strtoull(length, nullptr, 10) > kMaxBodyBytes) {
        return Refuse(server, connection, MHD_HTTP_CONTENT_TOO_LARGE, "request body too large\n");
      }
      *request_state = state = new RequestState();
      return MHD_YES;
    }
    if (*upload_data_size > 0) {
      if (state->body.size() + *upload_data_size > kMaxBodyBytes) {
        state->too_large = true;  // chunked bodies: read and dropped, refused at the end
      } else {
        state->body.append(upload_data, *upload_data_size);
      }
      *upload_data_size = 0;
      return MHD_YES;
    }
    if (state->too_large) {
      return Refuse(server, connection, MHD_HTTP_CONTENT_TOO_LARGE, "request body too large\n");
    }
    HttpRequest request;
    request.method = method;
    request.path = url;
    request.body = state->body.c_str();
    request.body_bytes = state->body.size();
    request.connection = connection;
    HttpResponse response;
    server->handler_->Handle(request, &response);
    return Queue(server, connection, response);
  }

  static void Completed(void* cls, MHD_Connection* connection, void** request_state,
                        MHD_RequestTerminationCode why) {
    delete static_cast<RequestState*>(*request_state);
    *request_state = nullptr;
  }
};

namespace {

// The listening address: IPv4 or IPv6 text.
struct BindAddress {
  sockaddr_storage storage{};
  bool ipv6 = false;
};

Result<BindAddress> ParseBindAddress(const char* text, uint16_t port) {
  BindAddress a;
  auto* v4 = reinterpret_cast<sockaddr_in*>(&a.storage);
  auto* v6 = reinterpret_cast<sockaddr_in6*>(&a.storage);
  if (inet_pton(AF_INET, text, &v4->sin_addr) == 1) {
    v4->sin_family = AF_INET;
    v4->sin_port = htons(port);
    return a;
  }
  if (inet_pton(AF_INET6, text, &v6->sin6_addr) == 1) {
    v6->sin6_family = AF_INET6;
    v6->sin6_port = htons(port);
    a.ipv6 = true;
    return a;
  }
  return Status::Error(StatusCode::kInvalidArgument,
                       "key 'http_bind': '%s' is not an IPv4 or IPv6 address", text);
}

}  // namespace

Status HttpServer::Start(const HttpServerConfig& config, HttpHandler* handler) {
  if (daemon_ != nullptr) {
    return Status::Error(StatusCode::kFailedPrecondition, "web server already started");
  }
  SH_ASSIGN_OR_RETURN(BindAddress address, ParseBindAddress(config.bind_address, config.port));
  handler_ = handler;
  // No internal thread: Loop() runs the server on a thread of ours, at our priority. select()
  // rather than epoll: in this external mode libmicrohttpd 0.9.75 with epoll kept connections
  // that clients had closed until their timeout, so a burst of slow clients locked others out
  // for that long. The connection limit keeps the sockets few (and libmicrohttpd refuses one
  // beyond FD_SETSIZE).
  unsigned flags = 0;
  if (address.ipv6) flags |= MHD_USE_IPv6;
  // HTTPS: libmicrohttpd's GnuTLS, the PEM pair given in memory (MHD_OPTION_ARRAY so that one
  // call serves both cases).
  const bool https = config.tls_cert_pem != nullptr && config.tls_key_pem != nullptr;
  MHD_OptionItem tls[] = {
      {MHD_OPTION_END, 0, nullptr}, {MHD_OPTION_END, 0, nullptr}, {MHD_OPTION_END, 0, nullptr}};
  if (https) {
    if (MHD_is_feature_supported(MHD_FEATURE_TLS) != MHD_YES) {
      return Status::Error(StatusCode::kUnimplemented,
                           "web server: this libmicrohttpd has no TLS (keys 'http_tls_cert', "
                           "'http_tls_key')");
    }
    flags |= MHD_USE_TLS;
    tls[0] = {MHD_OPTION_HTTPS_MEM_CERT, 0, const_cast<char*>(config.tls_cert_pem)};
    tls[1] = {MHD_OPTION_HTTPS_MEM_KEY, 0, const_cast<char*>(config.tls_key_pem)};
  }
  daemon_ = MHD_start_daemon(
      flags, config.port, nullptr, nullptr, &HttpServerCallbacks::Dispatch, this,
      MHD_OPTION_SOCK_ADDR, reinterpret_cast<sockaddr*>(&address.storage),
      MHD_OPTION_CONNECTION_LIMIT, kMaxConnections, MHD_OPTION_PER_IP_CONNECTION_LIMIT,
      kMaxConnectionsPerAddress, MHD_OPTION_CONNECTION_TIMEOUT, kConnectionTimeoutS,
      MHD_OPTION_CONNECTION_MEMORY_LIMIT, kConnectionMemoryBytes, MHD_OPTION_NOTIFY_COMPLETED,
      &HttpServerCallbacks::Completed, this, MHD_OPTION_ARRAY, tls, MHD_OPTION_END);
  if (daemon_ == nullptr && https) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "web server: cannot serve HTTPS on %s port %u: keys 'http_tls_cert' and "
                         "'http_tls_key' must be a PEM certificate and its own unencrypted key",
                         config.bind_address, config.port);
  }
  if (daemon_ == nullptr) {
    return Status::Error(StatusCode::kUnavailable, "web server: cannot listen on %s port %u",
                         config.bind_address, config.port);
  }
  https_ = https;
  const MHD_DaemonInfo* info = MHD_get_daemon_info(daemon_, MHD_DAEMON_INFO_BIND_PORT);
  port_ = info != nullptr ? info->port : config.port;
  stop_ = false;
  thread_ = std::thread([this] { Loop(); });
  return Status::Ok();
}

void HttpServer::Loop() {
  // A lower priority than the firmware's threads: a busy page waits, a trigger does not.
  (void)setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), kServerNice);
  while (!stop_.load()) MHD_run_wait(daemon_, 200);
}

void HttpServer::Stop() {
  if (daemon_ == nullptr) return;
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  MHD_stop_daemon(daemon_);
  daemon_ = nullptr;
}

}  // namespace sh::fw::web
