#include "hal/sim/socketcand_server.hpp"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cstring>
#include <new>

namespace sh::hal {
namespace {

int64_t MonotonicMs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000 + ts.tv_nsec / 1000000;
}

// Messages are short; anything beyond this in a log line is cut.
constexpr int kLoggedTextMax = 60;

}  // namespace

Status SocketcandServer::Start(SimCanBus* bus, const SocketcandServerConfig& config) {
  if (running_.load()) {
    return Status::Error(StatusCode::kFailedPrecondition, "socketcand server already running");
  }
  if (bus == nullptr || config.bind_address == nullptr || config.channel == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "socketcand server needs a bus, a bind address and a channel name");
  }
  if (config.handshake_settle_ms < 0) {
    return Status::Error(StatusCode::kInvalidArgument, "socketcand: negative settle time");
  }
  if (config.max_clients < 1 || config.max_clients > kSocketcandMaxClients) {
    return Status::Error(StatusCode::kOutOfRange, "socketcand: %zu client slots, 1..%zu supported",
                         config.max_clients, kSocketcandMaxClients);
  }
  constexpr int kMaxTimeoutMs = 600000;
  if (config.handshake_timeout_ms < 1 || config.handshake_timeout_ms > kMaxTimeoutMs ||
      config.idle_timeout_ms < 0 || config.idle_timeout_ms > kMaxTimeoutMs ||
      config.stall_timeout_ms < 1 || config.stall_timeout_ms > kMaxTimeoutMs) {
    return Status::Error(StatusCode::kOutOfRange,
                         "socketcand: handshake %d ms, idle %d ms or stall %d ms timeout outside "
                         "1..%d ms (idle: 0 = none)",
                         config.handshake_timeout_ms, config.idle_timeout_ms,
                         config.stall_timeout_ms, kMaxTimeoutMs);
  }
  config_ = config;
  // The buffers of the configured slots, once per start (never per message).
  buffer_bytes_ = 0;
  buffers_.reset(new (std::nothrow) char[BufferBytes(config.max_clients)]);
  if (buffers_ == nullptr) {
    return Status::Error(StatusCode::kResourceExhausted,
                         "socketcand: cannot allocate %zu bytes of buffers for %zu clients",
                         BufferBytes(config.max_clients), config.max_clients);
  }
  buffer_bytes_ = BufferBytes(config.max_clients);
  char* next = buffers_.get();
  for (size_t i = 0; i < kSocketcandMaxClients; ++i) {
    Client& c = clients_[i];
    c.in = c.out = nullptr;
    if (i >= config.max_clients) continue;
    c.in = next;
    c.out = next + kSocketcandInBufferBytes;
    next += kSocketcandInBufferBytes + kSocketcandOutBufferBytes;
  }
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(config.port);
  if (inet_pton(AF_INET, config.bind_address, &addr.sin_addr) != 1) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "socketcand: bind address '%s' is not an IPv4 address",
                         config.bind_address);
  }
  if (endpoint_ == nullptr) {
    SimCanEndpointConfig ep;
    ep.name = config.channel;
    ep.notify_fd = true;
    // socketcand's socket buffer: room for a device's largest burst (the answers to a full
    // receive queue of commands, result sets), which it relays faster than a bus would carry.
    ep.queue_depth = kSimCanMaxQueueDepth;
    Result<SimCanEndpoint*> added = bus->AddEndpoint(ep);
    if (!added.ok()) return added.status();
    endpoint_ = *added;
  }
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) {
    return Status::Error(StatusCode::kUnavailable, "socketcand: socket: %s", std::strerror(errno));
  }
  const int on = 1;
  setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof(on));
  if (bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 ||
      listen(fd, static_cast<int>(kSocketcandMaxClients)) != 0) {
    const int err = errno;
    close(fd);
    return Status::Error(StatusCode::kUnavailable, "socketcand: cannot listen on %s:%u: %s",
                         config.bind_address, config.port, std::strerror(err));
  }
  socklen_t len = sizeof(addr);
  getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
  wake_fd_ = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (wake_fd_ < 0) {
    close(fd);
    return Status::Error(StatusCode::kUnavailable, "socketcand: eventfd: %s", std::strerror(errno));
  }
  listen_fd_ = fd;
  stop_ = false;
  running_ = true;
  bridge_overflow_seen_ = endpoint_->stats().rx_dropped_overflow;
  const int err = pthread_create(&thread_, nullptr, &SocketcandServer::ThreadMain, this);
  if (err != 0) {
    running_ = false;
    close(listen_fd_);
    close(wake_fd_);
    listen_fd_ = wake_fd_ = -1;
    return Status::Error(StatusCode::kUnavailable, "socketcand: cannot start thread: %s",
                         std::strerror(err));
  }
  if (config_.log != nullptr) {
    std::fprintf(config_.log, "socketcand: listening on %s:%u, bus '%s'\n", config.bind_address,
                 port_, config.channel);
  }
  return Status::Ok();
}

void SocketcandServer::Stop() {
  if (!running_.load()) return;
  stop_ = true;
  const uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = write(wake_fd_, &one, sizeof(one));
  pthread_join(thread_, nullptr);
  for (size_t i = 0; i < config_.max_clients; ++i) {
    if (clients_[i].phase != Phase::kFree) DropClient(i, "server stopping");
  }
  close(listen_fd_);
  close(wake_fd_);
  listen_fd_ = wake_fd_ = -1;
  running_ = false;
}

SocketcandStats SocketcandServer::stats() const {
  SocketcandStats s;
  s.clients_accepted = clients_accepted_.load();
  s.clients_rejected = clients_rejected_.load();
  s.frames_to_clients = frames_to_clients_.load();
  s.frames_from_clients = frames_from_clients_.load();
  s.frames_without_client = frames_without_client_.load();
  s.frames_dropped_slow_client = frames_dropped_slow_.load();
  s.frames_lost_bridge = frames_lost_bridge_.load();
  s.clients_evicted = clients_evicted_.load();
  s.clients_timed_out = clients_timed_out_.load();
  s.malformed_messages = malformed_.load();
  s.bus_send_errors = bus_send_errors_.load();
  return s;
}

void* SocketcandServer::ThreadMain(void* self) {
  static_cast<SocketcandServer*>(self)->Run();
  return nullptr;
}

void SocketcandServer::Run() {
  while (!stop_.load()) {
    pollfd fds[3 + kSocketcandMaxClients];
    size_t client_of[3 + kSocketcandMaxClients];
    size_t n = 0;
    fds[n++] = {wake_fd_, POLLIN, 0};
    fds[n++] = {listen_fd_, POLLIN, 0};
    const bool room = ClientWithoutRoom() == kSocketcandMaxClients;
    fds[n++] = {endpoint_->notify_fd(), static_cast<short>(room ? POLLIN : 0), 0};
    const int64_t now = MonotonicMs();
    for (size_t i = 0; i < config_.max_clients; ++i) {
      const Client& c = clients_[i];
      if (c.phase == Phase::kFree) continue;
      // Backpressure: the commands of a client that has not read half its answers wait in TCP,
      // and so do everyone's while some client's output is full.
      short events = room && c.out_len <= kSocketcandOutBufferBytes / 2 ? POLLIN : 0;
      if (c.out_len > 0 && now >= c.raw_since_ms + config_.handshake_settle_ms) events |= POLLOUT;
      client_of[n] = i;
      fds[n++] = {c.fd, events, 0};
    }
    const int ready = poll(fds, n, PollTimeoutMs(now));
    if (ready < 0) {
      if (errno == EINTR) continue;
      if (config_.log != nullptr) {
        std::fprintf(config_.log, "socketcand: poll failed: %s\n", std::strerror(errno));
      }
      break;
    }
    if (fds[0].revents & POLLIN) continue;  // Stop() was called; the loop condition ends it
    if (fds[2].revents & POLLIN) DrainBus();
    for (size_t k = 3; k < n; ++k) {
      const size_t i = client_of[k];
      if (clients_[i].phase == Phase::kFree) continue;
      if (fds[k].revents & (POLLIN | POLLHUP | POLLERR)) ReadClient(i);
    }
    const int64_t after = MonotonicMs();
    for (size_t i = 0; i < config_.max_clients; ++i) {
      if (clients_[i].phase != Phase::kFree && clients_[i].out_len > 0) FlushClient(i, after);
    }
    CheckTimeouts(after);
    // Frames held back while a client's output was full, now that there may be room.
    if (ClientWithoutRoom() == kSocketcandMaxClients) DrainBus();
    CheckBridgeQueue();
    // New clients last: a slot freed by a timeout above is available to them.
    if (fds[1].revents & POLLIN) Accept();
  }
}

// Until the next settle time, timeout or stall check is due; -1 when none is.
int SocketcandServer::PollTimeoutMs(int64_t now_ms) const {
  int64_t next = -1;
  auto due = [&next, now_ms](int64_t at_ms) {
    const int64_t wait = at_ms > now_ms ? at_ms - now_ms : 0;
    if (next < 0 || wait < next) next = wait;
  };
  for (size_t i = 0; i < config_.max_clients; ++i) {
    const Client& c = clients_[i];
    switch (c.phase) {
      case Phase::kFree:
        continue;
      case Phase::kAwaitOpen:
      case Phase::kAwaitRawMode:
        due(c.connected_ms + config_.handshake_timeout_ms);
        break;
      case Phase::kRaw:
        if (c.out_len > 0) due(c.raw_since_ms + config_.handshake_settle_ms);
        if (config_.idle_timeout_ms > 0) due(c.last_message_ms + config_.idle_timeout_ms);
        break;
    }
    if (c.full_since_ms >= 0) due(c.full_since_ms + config_.stall_timeout_ms);
  }
  // The output of a client waiting for its settle time can still fill: look again soon.
  return next < 0 ? -1 : static_cast<int>(next < 1000 ? next : 1000);
}

void SocketcandServer::CheckTimeouts(int64_t now_ms) {
  for (size_t i = 0; i < config_.max_clients; ++i) {
    Client& c = clients_[i];
    const char* why = nullptr;
    if ((c.phase == Phase::kAwaitOpen || c.phase == Phase::kAwaitRawMode) &&
        now_ms >= c.connected_ms + config_.handshake_timeout_ms) {
      why = "no handshake within the handshake timeout";
    } else if (c.phase == Phase::kRaw && config_.idle_timeout_ms > 0 &&
               now_ms >= c.last_message_ms + config_.idle_timeout_ms) {
      why = "nothing sent within the idle timeout";
    } else if (c.phase != Phase::kFree && c.full_since_ms >= 0 &&
               now_ms >= c.full_since_ms + config_.stall_timeout_ms) {
      why = "not reading: output full for the stall timeout";
    }
    if (why == nullptr) continue;
    clients_timed_out_.fetch_add(1);
    char text[96];
    std::snprintf(text, sizeof(text), "< error %s >", why);
    [[maybe_unused]] const ssize_t w =
        send(c.fd, text, std::strlen(text), MSG_NOSIGNAL | MSG_DONTWAIT);
    DropClient(i, why);
  }
}

void SocketcandServer::CheckBridgeQueue() {
  const uint64_t overflow = endpoint_->stats().rx_dropped_overflow;
  if (overflow == bridge_overflow_seen_) return;
  const uint64_t lost = overflow - bridge_overflow_seen_;
  bridge_overflow_seen_ = overflow;
  frames_lost_bridge_.fetch_add(lost);
  if (config_.log != nullptr) {
    std::fprintf(config_.log,
                 "socketcand: %llu bus frames lost before reaching the clients (bridge queue "
                 "overflow)\n",
                 static_cast<unsigned long long>(lost));
  }
}

size_t SocketcandServer::FreeSlot() {
  size_t oldest = kSocketcandMaxClients;
  for (size_t i = 0; i < config_.max_clients; ++i) {
    const Client& c = clients_[i];
    if (c.phase == Phase::kFree) return i;
    if (c.phase != Phase::kRaw &&
        (oldest == kSocketcandMaxClients || c.connected_ms < clients_[oldest].connected_ms)) {
      oldest = i;
    }
  }
  if (oldest != kSocketcandMaxClients) {
    clients_evicted_.fetch_add(1);
    static constexpr char kEvicted[] = "< error slot taken by a new client before the handshake >";
    [[maybe_unused]] const ssize_t w =
        send(clients_[oldest].fd, kEvicted, sizeof(kEvicted) - 1, MSG_NOSIGNAL | MSG_DONTWAIT);
    DropClient(oldest, "evicted: still in the handshake when every slot was taken");
  }
  return oldest;
}

void SocketcandServer::Accept() {
  for (;;) {
    const int fd = accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) return;  // EAGAIN: no more pending connections
    const size_t slot = FreeSlot();
    if (slot == kSocketcandMaxClients) {
      static constexpr char kBusy[] = "< error too many clients >";
      clients_rejected_.fetch_add(1);  // counted before the client can see the refusal
      [[maybe_unused]] const ssize_t w = send(fd, kBusy, sizeof(kBusy) - 1, MSG_NOSIGNAL);
      close(fd);
      if (config_.log != nullptr) {
        std::fprintf(config_.log, "socketcand: client refused: all %zu slots in raw mode\n",
                     config_.max_clients);
      }
      continue;
    }
    const int on = 1;
    // Each handshake reply must leave in its own segment (see the header).
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof(on));
    // A fixed kernel send buffer: what a client has not read is bounded (not the megabytes of
    // loopback autotuning), so one that stopped reading shows as stalled within the timeout.
    const int send_buffer = static_cast<int>(kSocketcandOutBufferBytes);
    setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &send_buffer, sizeof(send_buffer));
    Client& c = clients_[slot];
    c.fd = fd;
    c.phase = Phase::kAwaitOpen;
    c.in_len = 0;
    c.out_len = 0;
    c.connected_ms = MonotonicMs();
    c.raw_since_ms = 0;
    c.last_message_ms = c.connected_ms;
    c.full_since_ms = -1;
    c.dropped = 0;
    clients_accepted_.fetch_add(1);
    connected_.fetch_add(1);
    if (config_.log != nullptr)
      std::fprintf(config_.log, "socketcand: client %zu connected\n", slot);
    SendNow(slot, "< hi >");
  }
}

bool SocketcandServer::SendNow(size_t index, const char* text) {
  Client& c = clients_[index];
  const size_t len = std::strlen(text);
  const ssize_t n = send(c.fd, text, len, MSG_NOSIGNAL | MSG_DONTWAIT);
  if (n != static_cast<ssize_t>(len)) {
    DropClient(index, "could not write a reply");
    return false;
  }
  return true;
}

void SocketcandServer::DropClient(size_t index, const char* why) {
  Client& c = clients_[index];
  if (c.phase == Phase::kFree) return;
  if (c.phase == Phase::kRaw) raw_mode_.fetch_sub(1);
  close(c.fd);
  c.fd = -1;
  c.phase = Phase::kFree;
  c.in_len = 0;
  c.out_len = 0;
  connected_.fetch_sub(1);
  if (config_.log != nullptr) {
    if (c.dropped > 0) {
      std::fprintf(config_.log,
                   "socketcand: client %zu disconnected (%s); %llu frames it did not read were "
                   "lost\n",
                   index, why, static_cast<unsigned long long>(c.dropped));
    } else {
      std::fprintf(config_.log, "socketcand: client %zu disconnected (%s)\n", index, why);
    }
  }
  c.dropped = 0;
  c.full_since_ms = -1;
}

void SocketcandServer::ReportMalformed(size_t index, const char* what, const char* text,
                                       size_t length) {
  malformed_.fetch_add(1);
  if (config_.log == nullptr || logged_errors_ >= kSocketcandLoggedErrorsMax) return;
  ++logged_errors_;
  const int shown = static_cast<int>(length < kLoggedTextMax ? length : kLoggedTextMax);
  std::fprintf(config_.log, "socketcand: client %zu: %s: '%.*s'%s\n", index, what, shown, text,
               logged_errors_ == kSocketcandLoggedErrorsMax ? " (further errors not logged)" : "");
}

void SocketcandServer::ReadClient(size_t index) {
  Client& c = clients_[index];
  const ssize_t n = recv(c.fd, c.in + c.in_len, kSocketcandInBufferBytes - c.in_len, MSG_DONTWAIT);
  if (n == 0) {
    DropClient(index, "closed by peer");
    return;
  }
  if (n < 0) {
    if (errno == EAGAIN || errno == EINTR) return;
    DropClient(index, std::strerror(errno));
    return;
  }
  c.in_len += static_cast<size_t>(n);
  for (;;) {
    const SocketcandScan scan = ScanSocketcandMessage(c.in, c.in_len);
    if (scan.skipped_garbage) {
      ReportMalformed(index, "skipped text outside '< >'", c.in,
                      scan.have_message ? scan.message_begin : scan.consumed);
    }
    if (scan.have_message) HandleMessage(index, c.in + scan.message_begin, scan.message_length);
    if (c.phase == Phase::kFree) return;  // dropped while handling
    if (scan.consumed > 0) {
      std::memmove(c.in, c.in + scan.consumed, c.in_len - scan.consumed);
      c.in_len -= scan.consumed;
    }
    if (!scan.have_message) break;
  }
}

void SocketcandServer::HandleMessage(size_t index, const char* text, size_t length) {
  Client& c = clients_[index];
  c.last_message_ms = MonotonicMs();
  SocketcandCommand cmd;
  const Status parsed = ParseSocketcandCommand(text, length, &cmd);
  if (!parsed.ok()) {
    ReportMalformed(index, parsed.message(), text, length);
    SendNow(index, "< error malformed command >");
    return;
  }
  switch (cmd.kind) {
    case SocketcandCommandKind::kEcho:
      SendNow(index, "< echo >");
      return;
    case SocketcandCommandKind::kOpen:
      if (c.phase != Phase::kAwaitOpen) break;
      if (std::strcmp(cmd.argument, config_.channel) != 0) {
        ReportMalformed(index, "open of an unknown bus", text, length);
        SendNow(index, "< error unknown bus >");
        return;
      }
      c.phase = Phase::kAwaitRawMode;
      SendNow(index, "< ok >");
      return;
    case SocketcandCommandKind::kRawMode:
      if (c.phase != Phase::kAwaitRawMode && c.phase != Phase::kRaw) break;
      if (c.phase == Phase::kAwaitRawMode) {
        c.phase = Phase::kRaw;
        c.raw_since_ms = MonotonicMs();
        raw_mode_.fetch_add(1);
      }
      SendNow(index, "< ok >");
      return;
    case SocketcandCommandKind::kSend: {
      if (c.phase != Phase::kRaw) break;
      CanFrame frame = cmd.frame;
      frame.timestamp_us = CanNowUs();
      // Counted before the frame becomes visible on the bus, so a reader never sees the frame
      // without the count.
      frames_from_clients_.fetch_add(1);
      const Status sent = endpoint_->Send(frame);
      if (!sent.ok()) {
        frames_from_clients_.fetch_sub(1);
        bus_send_errors_.fetch_add(1);
        if (config_.log != nullptr && logged_errors_ < kSocketcandLoggedErrorsMax) {
          ++logged_errors_;
          std::fprintf(config_.log, "socketcand: client %zu: frame not sent: %s\n", index,
                       sent.message());
        }
        return;
      }
      QueueToClients(frame, static_cast<int>(index));
      // Collect what the bus answered so far before the next command: a burst of commands
      // must not let the answers pile up in the bridge's bus queue until it overflows.
      DrainBus();
      return;
    }
    case SocketcandCommandKind::kOther:
      break;
  }
  ReportMalformed(index, "command not valid in this state", text, length);
  SendNow(index, "< error unexpected command >");
}

size_t SocketcandServer::ClientWithoutRoom() const {
  for (size_t i = 0; i < config_.max_clients; ++i) {
    const Client& c = clients_[i];
    if (c.phase == Phase::kRaw && c.out_len + kSocketcandMessageMax + 1 > kSocketcandOutBufferBytes)
      return i;
  }
  return kSocketcandMaxClients;
}

void SocketcandServer::DrainBus() {
  uint64_t counter;
  [[maybe_unused]] const ssize_t n = read(endpoint_->notify_fd(), &counter, sizeof(counter));
  CanFrame frame;
  for (;;) {
    // A client that has not read what it was sent holds the frames back in the bridge's bus
    // queue instead of losing them; after the stall timeout it is disconnected.
    const size_t full = ClientWithoutRoom();
    if (full != kSocketcandMaxClients) {
      if (clients_[full].full_since_ms < 0) clients_[full].full_since_ms = MonotonicMs();
      return;
    }
    Result<bool> got = endpoint_->Receive(&frame, 0);
    if (!got.ok() || !*got) return;
    if (frame.error) continue;  // controller reports stay on the simulated device side
    QueueToClients(frame, -1);
  }
}

void SocketcandServer::QueueToClients(const CanFrame& frame, int except_index) {
  char text[kSocketcandMessageMax + 1];
  text[0] = ' ';  // separator, see the header
  const size_t formatted = FormatSocketcandFrame(frame, text + 1, sizeof(text) - 1);
  if (formatted == 0) return;
  const size_t len = formatted + 1;
  bool any = false;
  for (size_t i = 0; i < config_.max_clients; ++i) {
    Client& c = clients_[i];
    if (c.phase != Phase::kRaw || static_cast<int>(i) == except_index) continue;
    any = true;
    if (c.out_len + len > kSocketcandOutBufferBytes) {
      // Only a frame one client sends to the others can meet a full buffer (bus frames wait
      // until there is room); counted and reported when the client goes or catches up.
      frames_dropped_slow_.fetch_add(1);
      if (c.dropped++ == 0 && config_.log != nullptr) {
        std::fprintf(config_.log, "socketcand: client %zu: output full, frames are being lost\n",
                     i);
      }
      if (c.full_since_ms < 0) c.full_since_ms = MonotonicMs();
      continue;
    }
    std::memcpy(c.out + c.out_len, text, len);
    c.out_len += len;
    frames_to_clients_.fetch_add(1);
  }
  if (!any && except_index < 0) frames_without_client_.fetch_add(1);
}

void SocketcandServer::FlushClient(size_t index, int64_t now_ms) {
  Client& c = clients_[index];
  if (now_ms < c.raw_since_ms + config_.handshake_settle_ms) return;
  const ssize_t n = send(c.fd, c.out, c.out_len, MSG_NOSIGNAL | MSG_DONTWAIT);
  if (n < 0) {
    if (errno == EAGAIN || errno == EINTR) return;
    DropClient(index, std::strerror(errno));
    return;
  }
  std::memmove(c.out, c.out + n, c.out_len - static_cast<size_t>(n));
  c.out_len -= static_cast<size_t>(n);
  if (c.full_since_ms >= 0 && c.out_len <= kSocketcandOutBufferBytes / 2) {
    c.full_since_ms = -1;  // reading again
    if (c.dropped > 0 && config_.log != nullptr) {
      std::fprintf(config_.log, "socketcand: client %zu reads again; %llu frames were lost\n",
                   index, static_cast<unsigned long long>(c.dropped));
    }
    c.dropped = 0;
  }
}

}  // namespace sh::hal
