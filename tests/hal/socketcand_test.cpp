#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>
#include <string>

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
  bool Connect(uint16_t port) {
    fd_ = socket(AF_INET, SOCK_STREAM, 0);
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
  Client clients[kSocketcandMaxClients];
  for (Client& c : clients) {
    ASSERT_TRUE(c.Connect(server_.port()));
    ASSERT_EQ(c.Read(), "< hi >");
  }
  Client extra;
  ASSERT_TRUE(extra.Connect(server_.port()));
  EXPECT_EQ(extra.Read().rfind("< error", 0), 0u);
  EXPECT_EQ(server_.stats().clients_rejected, 1u);
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
