// socketcand server for the simulated CAN bus: lets CAN tools on the host (python-can's
// "socketcand" interface, a PLC simulator) talk to the firmware running in simulation.
//
// Listens on a TCP address (127.0.0.1, port 0 = ephemeral) and joins the SimCanBus as one
// endpoint: frames other endpoints send are forwarded to every client in raw mode; frames a
// client sends ("< send ... >") go onto the bus and to the other raw-mode clients.
//
// Handshake as python-can 4.1 expects it: "< hi >" on connect, "< ok >" for "< open can0 >",
// "< ok >" for "< rawmode >", each in its own write. python-can compares each handshake read
// with the exact text, so frames are held back for handshake_settle_ms after the raw-mode
// "< ok >" to keep them out of that read. Each frame is preceded by one space: python-can 4.1
// drops one character after the last complete message it parsed, and without the space that
// character is the '<' of a message cut by a TCP segment boundary, which loses the message.
//
// Bounded: up to kSocketcandMaxClients clients, config.max_clients of them used, each with fixed
// input and output buffers; Start() allocates the buffers of the configured slots in one block
// (BufferBytes(max_clients)), so slots beyond the configuration take no memory. Nothing is lost
// without a trace:
//  - backpressure: a client's commands are read only while its output buffer is at most half
//    full, so a client that floods commands waits (in TCP) for the answers it has not read yet
//    instead of losing them; while any client's output is full, bus frames wait in the bridge's
//    bus queue (deep enough for a device's burst) instead of being dropped;
//  - a client whose output stays full for stall_timeout_ms (it does not read) is disconnected
//    and the others get the frames it held back; frames the bridge's bus queue lost anyway are
//    counted and logged;
//  - a client that has not finished the handshake within handshake_timeout_ms, or a raw-mode
//    client that sent nothing for idle_timeout_ms (when set), is disconnected, and when every
//    slot is taken a new client takes the slot of the oldest one still in its handshake, so
//    connections that say nothing cannot lock a PLC out.
// Malformed text is answered with "< error ... >", logged and skipped. The server thread is
// created in Start() and joined in Stop().
#pragma once

#include <pthread.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>

#include "hal/sim/can_sim_bus.hpp"
#include "hal/sim/socketcand_text.hpp"

namespace sh::hal {

inline constexpr size_t kSocketcandMaxClients = 16;  // capacity; config.max_clients are used
inline constexpr size_t kSocketcandInBufferBytes = 1024;
inline constexpr size_t kSocketcandOutBufferBytes = 65536;  // ~1,400 frames per client
inline constexpr size_t kSocketcandLoggedErrorsMax = 50;    // later errors are only counted

struct SocketcandServerConfig {
  const char* bind_address = "127.0.0.1";
  uint16_t port = 0;             // 0: the kernel picks a free port; read it with port()
  const char* channel = "can0";  // the bus name clients must "open"
  int handshake_settle_ms = 20;
  size_t max_clients = 4;           // slots, 1..kSocketcandMaxClients
  int handshake_timeout_ms = 2000;  // connect to raw mode, 1..600000
  int idle_timeout_ms = 0;          // raw mode without a message from the client; 0 = no limit
  int stall_timeout_ms = 2000;      // output full without the client reading, 1..600000
  FILE* log = stderr;               // connection events and malformed input; nullptr = silent
};

struct SocketcandStats {
  uint64_t clients_accepted = 0;
  uint64_t clients_rejected = 0;       // all slots busy with clients past their handshake
  uint64_t clients_evicted = 0;        // still in the handshake when a new client needed the slot
  uint64_t clients_timed_out = 0;      // handshake, idle or stall timeout
  uint64_t frames_to_clients = 0;      // frame messages queued to clients
  uint64_t frames_from_clients = 0;    // "send" commands put on the bus
  uint64_t frames_without_client = 0;  // bus frames seen while no client was in raw mode
  uint64_t frames_dropped_slow_client = 0;  // a client's output was full (it was not reading)
  uint64_t frames_lost_bridge = 0;          // the bridge's bus queue overflowed
  uint64_t malformed_messages = 0;
  uint64_t bus_send_errors = 0;  // client frames the bus refused (bus-off, queue full)
};

class SocketcandServer {
 public:
  SocketcandServer() = default;
  ~SocketcandServer() { Stop(); }
  SocketcandServer(const SocketcandServer&) = delete;
  SocketcandServer& operator=(const SocketcandServer&) = delete;

  // Binds, listens, joins `bus` (first call only; the endpoint is reused after Stop()) and
  // starts the server thread. The strings in config must outlive the server.
  Status Start(SimCanBus* bus, const SocketcandServerConfig& config);
  // Closes all connections and joins the thread. Safe to call twice.
  void Stop();

  uint16_t port() const { return port_; }
  bool running() const { return running_.load(); }
  size_t connected_clients() const { return connected_.load(); }
  // Clients past the handshake that receive bus frames.
  size_t raw_mode_clients() const { return raw_mode_.load(); }
  SocketcandStats stats() const;
  // The client buffers Start() allocates for max_clients slots.
  static constexpr size_t BufferBytes(size_t max_clients) {
    return max_clients * (kSocketcandInBufferBytes + kSocketcandOutBufferBytes);
  }
  // The client buffers allocated by the last Start() (0 before it).
  size_t buffer_bytes() const { return buffer_bytes_; }
  // The server's own endpoint on the bus (for fault injection in tests).
  SimCanEndpoint* endpoint() const { return endpoint_; }

 private:
  enum class Phase : uint8_t { kFree, kAwaitOpen, kAwaitRawMode, kRaw };
  struct Client {
    int fd = -1;
    Phase phase = Phase::kFree;
    int64_t connected_ms = 0;
    int64_t raw_since_ms = 0;
    int64_t last_message_ms = 0;  // last message from the client
    int64_t full_since_ms = -1;   // output full since then (-1: not full)
    uint64_t dropped = 0;         // frames lost because the output was full
    char* in = nullptr;           // kSocketcandInBufferBytes in buffers_
    size_t in_len = 0;
    char* out = nullptr;  // kSocketcandOutBufferBytes in buffers_
    size_t out_len = 0;
  };

  static void* ThreadMain(void* self);
  void Run();
  void Accept();
  size_t FreeSlot();  // a free slot, else the oldest client in its handshake (evicted), else none
  void CheckTimeouts(int64_t now_ms);
  int PollTimeoutMs(int64_t now_ms) const;
  void CheckBridgeQueue();
  // A raw-mode client whose output cannot take one more frame, or kSocketcandMaxClients.
  size_t ClientWithoutRoom() const;
  void ReadClient(size_t index);
  void HandleMessage(size_t index, const char* text, size_t length);
  void DrainBus();
  void QueueToClients(const CanFrame& frame, int except_index);
  void FlushClient(size_t index, int64_t now_ms);
  bool SendNow(size_t index, const char* text);
  void DropClient(size_t index, const char* why);
  void ReportMalformed(size_t index, const char* what, const char* text, size_t length);

  SocketcandServerConfig config_;
  SimCanEndpoint* endpoint_ = nullptr;
  int listen_fd_ = -1;
  int wake_fd_ = -1;
  uint16_t port_ = 0;
  pthread_t thread_{};
  std::atomic<bool> running_{false};
  std::atomic<bool> stop_{false};
  std::atomic<size_t> connected_{0};
  std::atomic<size_t> raw_mode_{0};
  Client clients_[kSocketcandMaxClients];
  std::unique_ptr<char[]> buffers_;  // the in and out buffers of config_.max_clients slots
  size_t buffer_bytes_ = 0;

  // Written by the server thread, read by stats() from others.
  std::atomic<uint64_t> clients_accepted_{0}, clients_rejected_{0}, clients_evicted_{0},
      clients_timed_out_{0}, frames_to_clients_{0}, frames_from_clients_{0},
      frames_without_client_{0}, frames_dropped_slow_{0}, frames_lost_bridge_{0}, malformed_{0},
      bus_send_errors_{0};
  uint64_t bridge_overflow_seen_ = 0;  // the endpoint's rx_dropped_overflow already counted
  size_t logged_errors_ = 0;
};

}  // namespace sh::hal
