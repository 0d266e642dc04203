#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "hal/sim/socketcand_server.hpp"
#include "hal/sim/socketcand_text.hpp"

namespace sh::hal {
namespace {

Status Parse(const char* text, SocketcandCommand* cmd) {
  return ParseSocketcandCommand(text, std::strlen(text), cmd);
}

TEST(SocketcandTextTest, ParsesPythonCanSendCommands) {
  SocketcandCommand cmd;
  ASSERT_TRUE(Parse("< send 201 4 1 0 ff a >", &cmd).ok());
  EXPECT_EQ(cmd.kind, SocketcandCommandKind::kSend);
  EXPECT_EQ(cmd.frame.id, 0x201u);
  EXPECT_FALSE(cmd.frame.extended);
  ASSERT_EQ(cmd.frame.len, 4);
  EXPECT_EQ(cmd.frame.data[0], 1);
  EXPECT_EQ(cmd.frame.data[2], 0xFF);
  EXPECT_EQ(cmd.frame.data[3], 0x0A);

  ASSERT_TRUE(Parse("< send 1ABCDEF0 0  >", &cmd).ok());
  EXPECT_TRUE(cmd.frame.extended);
  EXPECT_EQ(cmd.frame.len, 0);
  ASSERT_TRUE(Parse("< send 00000181 1 5 >", &cmd).ok());
  EXPECT_TRUE(cmd.frame.extended);  // 8 id digits mean an extended id, as in socketcand

  ASSERT_TRUE(Parse("< open can0 >", &cmd).ok());
  EXPECT_EQ(cmd.kind, SocketcandCommandKind::kOpen);
  EXPECT_STREQ(cmd.argument, "can0");
  ASSERT_TRUE(Parse("<rawmode>", &cmd).ok());
  EXPECT_EQ(cmd.kind, SocketcandCommandKind::kRawMode);
  ASSERT_TRUE(Parse("< bcmmode >", &cmd).ok());
  EXPECT_EQ(cmd.kind, SocketcandCommandKind::kOther);
  EXPECT_STREQ(cmd.argument, "bcmmode");
}

TEST(SocketcandTextTest, RejectsMalformedCommandsWithAReason) {
  const char* bad[] = {"< >",
                       "< send >",
                       "< send 201 >",
                       "< send 201 3 1 2 >",
                       "< send 201 2 1 2 3 >",
                       "< send 201 9 1 2 3 4 5 6 7 8 9 >",
                       "< send 2G1 1 1 >",
                       "< send 201 1 100 >",
                       "< send 3FFFFFFFF 1 1 >",
                       "< open >",
                       "send 201 1 1",
                       "< send 201 1 1 1 1 1 1 1 1 1 1 1 1 1 >"};
  for (const char* text : bad) {
    SocketcandCommand cmd;
    const Status s = Parse(text, &cmd);
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument) << text;
    EXPECT_GT(std::strlen(s.message()), 5u) << text;
  }
}

TEST(SocketcandTextTest, FormatsFramesAsPythonCanParsesThem) {
  CanFrame f;
  f.id = 0x181;
  f.len = 8;
  for (uint8_t i = 0; i < 8; ++i) f.data[i] = static_cast<uint8_t>(i + 1);
  f.timestamp_us = 1700000000000001ull;
  char out[kSocketcandMessageMax];
  ASSERT_GT(FormatSocketcandFrame(f, out, sizeof(out)), 0u);
  EXPECT_STREQ(out, "< frame 181 1700000000.000001 0102030405060708 >");
  f.len = 0;
  ASSERT_GT(FormatSocketcandFrame(f, out, sizeof(out)), 0u);
  EXPECT_STREQ(out, "< frame 181 1700000000.000001  >");
}

TEST(SocketcandTextTest, ScannerSplitsMessagesAndSkipsGarbage) {
  const char buffer[] = "junk< ok >< send 1 0  >  < partial";
  size_t pos = 0;
  const size_t len = sizeof(buffer) - 1;
  SocketcandScan scan = ScanSocketcandMessage(buffer + pos, len - pos);
  ASSERT_TRUE(scan.have_message);
  EXPECT_TRUE(scan.skipped_garbage);
  EXPECT_EQ(std::string(buffer + pos + scan.message_begin, scan.message_length), "< ok >");
  pos += scan.consumed;
  scan = ScanSocketcandMessage(buffer + pos, len - pos);
  ASSERT_TRUE(scan.have_message);
  EXPECT_FALSE(scan.skipped_garbage);
  EXPECT_EQ(std::string(buffer + pos + scan.message_begin, scan.message_length), "< send 1 0  >");
  pos += scan.consumed;
  scan = ScanSocketcandMessage(buffer + pos, len - pos);
  EXPECT_FALSE(scan.have_message);
  EXPECT_EQ(std::string(buffer + pos + scan.consumed), "< partial");  // kept for more data

  // An unterminated message beyond the limit is discarded instead of filling the buffer.
  std::string long_text = "<" + std::string(kSocketcandMessageMax + 5, 'x');
  scan = ScanSocketcandMessage(long_text.data(), long_text.size());
  EXPECT_FALSE(scan.have_message);
  EXPECT_TRUE(scan.skipped_garbage);
  EXPECT_EQ(scan.consumed, long_text.size());
  // A '<' inside an open message restarts the scan at the new message.
  const char nested[] = "< sen< ok >";
  scan = ScanSocketcandMessage(nested, sizeof(nested) - 1);
  ASSERT_TRUE(scan.have_message);
  EXPECT_TRUE(scan.skipped_garbage);
  EXPECT_EQ(std::string(nested + scan.message_begin, scan.message_length), "< ok >");
}

// ---------------------------------------------------------------------------- server

// Minimal blocking TCP client that reads whole "< ... >" messages.
class Client {
 public:
  // receive_buffer > 0: a small socket receive buffer, for a client that does not read.
  bool Connect(uint16_t port, int receive_buffer = 0) {
    fd_ = socket(AF_INET, SOCK_STREAM, 0);
    if (receive_buffer > 0) {
      setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof(receive_buffer));
    }
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(port);
    inet_pton(AF_INET, "127.0.0.1", &addr.sin_addr);
    return connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0;
  }
  ~Client() { Close(); }
  void Close() {
    if (fd_ >= 0) close(fd_);
    fd_ = -1;
  }
  bool Write(const std::string& text) {
    return send(fd_, text.data(), text.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(text.size());
  }
  // Next message, or "" after timeout_ms / on close.
  std::string Read(int timeout_ms = 2000) {
    for (;;) {
      const size_t open = buffer_.find('<');
      const size_t close_pos = buffer_.find('>', open == std::string::npos ? 0 : open);
      if (open != std::string::npos && close_pos != std::string::npos) {
        std::string msg = buffer_.substr(open, close_pos + 1 - open);
        buffer_.erase(0, close_pos + 1);
        return msg;
      }
      pollfd pfd{fd_, POLLIN, 0};
      if (poll(&pfd, 1, timeout_ms) <= 0) return "";
      char chunk[512];
      const ssize_t n = recv(fd_, chunk, sizeof(chunk), 0);
      if (n <= 0) return "";
      buffer_.append(chunk, static_cast<size_t>(n));
    }
  }
  bool Handshake() {
    return Read() == "< hi >" && Write("< open can0 >") && Read() == "< ok >" &&
           Write("< rawmode >") && Read() == "< ok >";
  }

 private:
  int fd_ = -1;
  std::string buffer_;
};

class SocketcandServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    SimCanEndpointConfig config;
    config.name = "firmware";
    Result<SimCanEndpoint*> fw = bus_.AddEndpoint(config);
    ASSERT_TRUE(fw.ok());
    firmware_ = *fw;
    SocketcandServerConfig server_config;
    server_config.handshake_settle_ms = 5;
    server_config.log = nullptr;
    ASSERT_TRUE(server_.Start(&bus_, server_config).ok());
    ASSERT_NE(server_.port(), 0);
  }
  // Waits until the server has n clients in the connected count.
  void WaitForClients(size_t n) {
    for (int i = 0; i < 200 && server_.connected_clients() != n; ++i) usleep(5000);
    ASSERT_EQ(server_.connected_clients(), n);
  }

  SimCanBus bus_;
  SimCanEndpoint* firmware_ = nullptr;
  SocketcandServer server_;
};

TEST_F(SocketcandServerTest, BridgesFramesBothWays) {
  Client client;
  ASSERT_TRUE(client.Connect(server_.port()));
  ASSERT_TRUE(client.Handshake());

  CanFrame out;
  out.id = 0x181;
  out.len = 3;
  out.data[0] = 0xAB;
  out.data[1] = 0x01;
  out.data[2] = 0x00;
  ASSERT_TRUE(firmware_->Send(out).ok());
  const std::string msg = client.Read();
  ASSERT_EQ(msg.rfind("< frame 181 ", 0), 0u) << msg;
  EXPECT_NE(msg.find(" ab0100 >"), std::string::npos) << msg;

  ASSERT_TRUE(client.Write("< send 201 3 1 2a 0 >"));
  CanFrame in;
  Result<bool> got = firmware_->Receive(&in, 2000);
  ASSERT_TRUE(got.ok() && *got);
  EXPECT_EQ(in.id, 0x201u);
  ASSERT_EQ(in.len, 3);
  EXPECT_EQ(in.data[1], 0x2A);
  EXPECT_EQ(server_.stats().frames_from_clients, 1u);
}

TEST_F(SocketcandServerTest, MalformedTextGetsAnErrorAndTheSessionContinues) {
  Client client;
  ASSERT_TRUE(client.Connect(server_.port()));
  ASSERT_TRUE(client.Handshake());
  ASSERT_TRUE(client.Write("< send 201 9 x >"));
  EXPECT_EQ(client.Read().rfind("< error", 0), 0u);
  ASSERT_TRUE(client.Write("garbage without brackets < bogus >"));
  EXPECT_EQ(client.Read().rfind("< error", 0), 0u);
  ASSERT_TRUE(client.Write(std::string(3000, 'z')));  // longer than the input buffer
  ASSERT_TRUE(client.Write("< send 201 1 4 >"));
  CanFrame in;
  Result<bool> got = firmware_->Receive(&in, 2000);
  ASSERT_TRUE(got.ok() && *got);
  EXPECT_EQ(in.data[0], 4);
  EXPECT_GE(server_.stats().malformed_messages, 3u);
}

TEST_F(SocketcandServerTest, WrongBusNameIsRefused) {
  Client client;
  ASSERT_TRUE(client.Connect(server_.port()));
  ASSERT_EQ(client.Read(), "< hi >");
  ASSERT_TRUE(client.Write("< open vcan7 >"));
  EXPECT_EQ(client.Read().rfind("< error", 0), 0u);
  ASSERT_TRUE(client.Write("< send 201 1 4 >"));  // not in raw mode yet
  EXPECT_EQ(client.Read().rfind("< error", 0), 0u);
}

TEST_F(SocketcandServerTest, ClientsCanDisconnectAndReconnect) {
  {
    Client first;
    ASSERT_TRUE(first.Connect(server_.port()));
    ASSERT_TRUE(first.Handshake());
    WaitForClients(1);
  }
  WaitForClients(0);
  Client second;
  ASSERT_TRUE(second.Connect(server_.port()));
  ASSERT_TRUE(second.Handshake());
  CanFrame out;
  out.id = 0x701;
  out.len = 1;
  out.data[0] = 0x05;
  ASSERT_TRUE(firmware_->Send(out).ok());
  EXPECT_EQ(second.Read().rfind("< frame 701 ", 0), 0u);
  EXPECT_EQ(server_.stats().clients_accepted, 2u);
}

TEST_F(SocketcandServerTest, FramesFromOneClientReachTheOthers) {
  Client a, b;
  ASSERT_TRUE(a.Connect(server_.port()));
  ASSERT_TRUE(a.Handshake());
  ASSERT_TRUE(b.Connect(server_.port()));
  ASSERT_TRUE(b.Handshake());
  usleep(20000);  // let b's handshake settle time pass so the frame is not held back
  ASSERT_TRUE(a.Write("< send 0 2 1 0 >"));
  const std::string msg = b.Read();
  EXPECT_EQ(msg.rfind("< frame 0 ", 0), 0u) << msg;
}

TEST_F(SocketcandServerTest, ExtraClientsBeyondTheLimitAreTurnedAway) {
  // Every slot held by a client past its handshake: a new one is refused.
  Client clients[4];
  for (Client& c : clients) {
    ASSERT_TRUE(c.Connect(server_.port()));
    ASSERT_TRUE(c.Handshake());
  }
  Client extra;
  ASSERT_TRUE(extra.Connect(server_.port()));
  EXPECT_EQ(extra.Read().rfind("< error", 0), 0u);
  EXPECT_EQ(server_.stats().clients_rejected, 1u);
}

// Connections that say nothing cannot lock the PLC out: a new client takes the slot of the
// oldest one still in its handshake.
TEST_F(SocketcandServerTest, SilentConnectionsGiveWayToANewClient) {
  Client silent[4];
  for (Client& c : silent) {
    ASSERT_TRUE(c.Connect(server_.port()));
    ASSERT_EQ(c.Read(), "< hi >");
  }
  Client plc;
  ASSERT_TRUE(plc.Connect(server_.port()));
  ASSERT_TRUE(plc.Handshake());
  EXPECT_EQ(server_.stats().clients_evicted, 1u);
  EXPECT_EQ(silent[0].Read().rfind("< error slot taken", 0), 0u) << "the oldest one goes";
  EXPECT_EQ(silent[0].Read(), "") << "and is closed";
}

TEST_F(SocketcandServerTest, StopAndRestartOnANewPort) {
  server_.Stop();
  EXPECT_FALSE(server_.running());
  SocketcandServerConfig config;
  config.log = nullptr;
  ASSERT_TRUE(server_.Start(&bus_, config).ok());
  Client client;
  ASSERT_TRUE(client.Connect(server_.port()));
  EXPECT_TRUE(client.Handshake());
}

// A server on its own bus with a "firmware" that answers every command frame it receives with
// `answers` frames, as the firmware answers a refused trigger with an ack, an EMCY and an error
// reset.
class Answerer {
 public:
  Answerer(SimCanBus* bus, int answers) : answers_(answers) {
    SimCanEndpointConfig config;
    config.name = "firmware";
    config.filter_ids[0] = 0x201;
    config.filter_count = 1;
    endpoint_ = *bus->AddEndpoint(config);
    thread_ = std::thread([this] { Run(); });
  }
  ~Answerer() {
    stop_ = true;
    thread_.join();
  }
  std::atomic<uint64_t> commands{0};
  SimCanEndpoint* endpoint() const { return endpoint_; }

 private:
  void Run() {
    while (!stop_) {
      CanFrame in;
      Result<bool> got = endpoint_->Receive(&in, 10);
      if (!got.ok() || !*got) continue;
      ++commands;
      for (int k = 0; k < answers_; ++k) {
        CanFrame out;
        out.id = 0x481;
        out.len = 4;
        std::memcpy(out.data, in.data, 3);  // the request id in bytes 1-2
        out.data[3] = static_cast<uint8_t>(k);
        while (!endpoint_->Send(out).ok()) usleep(100);
      }
    }
  }
  int answers_;
  SimCanEndpoint* endpoint_ = nullptr;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

SocketcandServerConfig QuietConfig() {
  SocketcandServerConfig c;
  c.handshake_settle_ms = 5;
  c.log = nullptr;
  return c;
}

// 3,000 commands sent back to back, each answered with three frames (9,000 frames, about 400 KB
// of text, more than the client's output buffer holds): the bridge loses none of them on the
// way back, and a command the device could not take is counted where it was lost.
TEST(SocketcandFloodTest, ACommandFloodGetsEveryAnswer) {
  SimCanBus bus;
  Answerer firmware(&bus, 3);
  SocketcandServer server;
  ASSERT_TRUE(server.Start(&bus, QuietConfig()).ok());
  Client client;
  ASSERT_TRUE(client.Connect(server.port()));
  ASSERT_TRUE(client.Handshake());
  usleep(20000);  // past the settle time
  constexpr int kCommands = 3000;
  std::string flood;
  for (int i = 0; i < kCommands; ++i) {
    char text[48];
    std::snprintf(text, sizeof(text), "< send 201 3 1 %x %x >", i & 0xFF, i >> 8);
    flood += text;
  }
  // Written from another thread: with backpressure the server reads the commands only as fast
  // as the answers are read, so the write completes while this thread reads.
  std::thread writer([&] { ASSERT_TRUE(client.Write(flood)); });
  std::vector<int> answers(kCommands, 0);
  int received = 0;
  while (received < 3 * kCommands) {
    const std::string msg = client.Read(2000);
    if (msg.empty()) break;
    unsigned id = 0;
    char data[32] = {};
    if (std::sscanf(msg.c_str(), "< frame %x %*s %31s >", &id, data) != 2 || id != 0x481) continue;
    const int request = int(std::strtoul(std::string(data + 2, 4).c_str(), nullptr, 16));
    const int swapped = ((request & 0xFF) << 8) | (request >> 8);  // little-endian u16
    ASSERT_LT(swapped, kCommands);
    ++answers[swapped];
    ++received;
  }
  writer.join();
  // What the device could not take it lost in its own receive queue, where the firmware counts
  // and reports it (EMCY 0x8110); everything it answered reached the client.
  const uint64_t taken = firmware.commands.load();
  const uint64_t overrun = firmware.endpoint()->stats().rx_dropped_overflow;
  EXPECT_EQ(taken + overrun, uint64_t{kCommands});
  EXPECT_EQ(received, int(3 * taken));
  int answered = 0;
  for (int i = 0; i < kCommands; ++i) {
    ASSERT_TRUE(answers[i] == 0 || answers[i] == 3) << "command " << i;
    answered += answers[i] == 3;
  }
  EXPECT_EQ(answered, int(taken));
  EXPECT_EQ(server.stats().frames_dropped_slow_client, 0u);
  EXPECT_EQ(server.stats().frames_lost_bridge, 0u);
}

TEST(SocketcandTimeoutTest, AClientWithoutAHandshakeIsClosedAfterTheTimeout) {
  SimCanBus bus;
  SocketcandServer server;
  SocketcandServerConfig config = QuietConfig();
  config.handshake_timeout_ms = 200;
  ASSERT_TRUE(server.Start(&bus, config).ok());
  Client silent;
  ASSERT_TRUE(silent.Connect(server.port()));
  ASSERT_EQ(silent.Read(), "< hi >");
  EXPECT_EQ(silent.Read(5000), "< error no handshake within the handshake timeout >");
  EXPECT_EQ(silent.Read(5000), "") << "closed";
  for (int i = 0; i < 200 && server.connected_clients() != 0; ++i) usleep(5000);
  EXPECT_EQ(server.connected_clients(), 0u);
  EXPECT_EQ(server.stats().clients_timed_out, 1u);
}

TEST(SocketcandTimeoutTest, AnIdleClientIsClosedOnlyWhenAnIdleTimeoutIsSet) {
  SimCanBus bus;
  SocketcandServer server;
  SocketcandServerConfig config = QuietConfig();
  config.idle_timeout_ms = 200;
  ASSERT_TRUE(server.Start(&bus, config).ok());
  Client idle, talking;
  ASSERT_TRUE(idle.Connect(server.port()));
  ASSERT_TRUE(idle.Handshake());
  ASSERT_TRUE(talking.Connect(server.port()));
  ASSERT_TRUE(talking.Handshake());
  // The talking client keeps sending echoes; the idle one says nothing.
  for (int i = 0; i < 8; ++i) {
    ASSERT_TRUE(talking.Write("< echo >"));
    ASSERT_EQ(talking.Read(), "< echo >");
    usleep(60000);
  }
  EXPECT_EQ(idle.Read(5000), "< error nothing sent within the idle timeout >");
  for (int i = 0; i < 200 && server.connected_clients() != 1; ++i) usleep(5000);
  EXPECT_EQ(server.connected_clients(), 1u);
  ASSERT_TRUE(talking.Write("< echo >"));
  EXPECT_EQ(talking.Read(), "< echo >");
}

// A client that stops reading holds the frames back for everyone until the stall timeout closes
// it; then the others get every frame, none lost.
TEST(SocketcandTimeoutTest, AClientThatDoesNotReadIsClosedAndTheOthersGetEverything) {
  SimCanBus bus;
  SimCanEndpointConfig device_config;
  device_config.name = "device";
  SimCanEndpoint* device = *bus.AddEndpoint(device_config);
  SocketcandServer server;
  SocketcandServerConfig config = QuietConfig();
  config.stall_timeout_ms = 200;
  ASSERT_TRUE(server.Start(&bus, config).ok());
  Client deaf, reader;
  ASSERT_TRUE(deaf.Connect(server.port(), 4096));
  ASSERT_TRUE(deaf.Handshake());
  ASSERT_TRUE(reader.Connect(server.port()));
  ASSERT_TRUE(reader.Handshake());
  usleep(20000);
  // More frames than the deaf client's output buffer and socket buffers take.
  // The device sends no faster than the reading client takes the frames (as a real bus would
  // not outrun a PLC that keeps up), so only the deaf client falls behind.
  constexpr int kFrames = 60000;
  std::atomic<int> got{0};
  std::atomic<bool> reader_gone{false};
  std::thread sender([&] {
    for (int i = 0; i < kFrames && !reader_gone; ++i) {
      CanFrame f;
      f.id = 0x701;
      f.len = 2;
      f.data[0] = uint8_t(i);
      f.data[1] = uint8_t(i >> 8);
      while (!device->Send(f).ok()) usleep(100);
      while (i - got.load() > 256 && !reader_gone) usleep(200);
    }
  });
  while (got < kFrames) {
    const std::string msg = reader.Read(5000);
    if (msg.empty()) break;
    if (msg.rfind("< frame 701 ", 0) == 0) ++got;
  }
  reader_gone = true;
  sender.join();
  EXPECT_EQ(got, kFrames);
  // The deaf client goes once its output has been full for the stall timeout.
  for (int i = 0; i < 500 && server.connected_clients() != 1; ++i) usleep(10000);
  EXPECT_EQ(server.stats().clients_timed_out, 1u);
  EXPECT_EQ(server.stats().frames_lost_bridge, 0u);
  EXPECT_EQ(server.connected_clients(), 1u);
}

TEST(SocketcandServerConfigTest, SlotCountIsConfigurableAndBounded) {
  SimCanBus bus;
  SocketcandServer server;
  SocketcandServerConfig config = QuietConfig();
  config.max_clients = 0;
  EXPECT_EQ(server.Start(&bus, config).code(), StatusCode::kOutOfRange);
  config.max_clients = kSocketcandMaxClients + 1;
  const Status s = server.Start(&bus, config);
  EXPECT_EQ(s.code(), StatusCode::kOutOfRange);
  EXPECT_NE(std::string(s.message()).find("1..16 supported"), std::string::npos) << s.message();
  config.max_clients = 2;
  ASSERT_TRUE(server.Start(&bus, config).ok());
  Client a, b, c;
  ASSERT_TRUE(a.Connect(server.port()));
  ASSERT_TRUE(a.Handshake());
  ASSERT_TRUE(b.Connect(server.port()));
  ASSERT_TRUE(b.Handshake());
  ASSERT_TRUE(c.Connect(server.port()));
  EXPECT_EQ(c.Read(), "< error too many clients >");
}

// The client buffers are those of the configured slots: N slots take N clients' buffers, and
// the N+1-th client is refused.
TEST(SocketcandServerConfigTest, BufferMemoryScalesWithTheSlotCount) {
  EXPECT_EQ(SocketcandServer::BufferBytes(1), kSocketcandInBufferBytes + kSocketcandOutBufferBytes);
  for (size_t slots : {size_t{1}, size_t{3}}) {
    SimCanBus bus;
    SocketcandServer server;
    EXPECT_EQ(server.buffer_bytes(), 0u);
    SocketcandServerConfig config = QuietConfig();
    config.max_clients = slots;
    ASSERT_TRUE(server.Start(&bus, config).ok());
    EXPECT_EQ(server.buffer_bytes(), SocketcandServer::BufferBytes(slots));
    EXPECT_EQ(server.buffer_bytes(), slots * SocketcandServer::BufferBytes(1));
    std::vector<Client> clients(slots + 1);
    for (size_t i = 0; i < slots; ++i) {
      ASSERT_TRUE(clients[i].Connect(server.port()));
      ASSERT_TRUE(clients[i].Handshake());
    }
    ASSERT_TRUE(clients[slots].Connect(server.port()));
    EXPECT_EQ(clients[slots].Read(), "< error too many clients >");
    EXPECT_EQ(server.stats().clients_rejected, 1u);
    // Every slot's buffers carry frames: a bus frame reaches each client.
    SimCanEndpointConfig device_config;
    device_config.name = "device";
    Result<SimCanEndpoint*> device = bus.AddEndpoint(device_config);
    ASSERT_TRUE(device.ok());
    CanFrame frame;
    frame.id = 0x181;
    frame.len = 1;
    frame.data[0] = 0x5a;
    ASSERT_TRUE((*device)->Send(frame).ok());
    for (size_t i = 0; i < slots; ++i) EXPECT_EQ(clients[i].Read().rfind("< frame 181 ", 0), 0u);
  }
}

TEST(SocketcandServerConfigTest, RejectsABadBindAddress) {
  SimCanBus bus;
  SocketcandServer server;
  SocketcandServerConfig config;
  config.bind_address = "localhost:99";
  config.log = nullptr;
  const Status s = server.Start(&bus, config);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(s.message()).find("localhost:99"), std::string::npos);
}

}  // namespace
}  // namespace sh::hal
