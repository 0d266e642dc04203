// The commissioning page over real HTTP (the server on 127.0.0.1, a fake firmware behind it):
// actions and settings only from a logged-in session with its CSRF token, nothing done
// otherwise; no path outside the page's files and record_dir; oversized headers and bodies
// refused; settings validated as the configuration file is and written back with its comments;
// the live snapshot filled without the heap.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "firmware/web/http_server.hpp"
#include "firmware/web/json_writer.hpp"
#include "firmware/web/live_snapshot.hpp"
#include "firmware/web/recordings.hpp"
#include "firmware/web/web_app.hpp"
#include "firmware/web/web_auth.hpp"
#include "firmware/web/web_settings.hpp"
#include "tests/support/counting_allocator.hpp"
#include "tests/support/temp_dir.hpp"

namespace sh::fw::web {
namespace {

class FakeTarget final : public WebTarget {
 public:
  WebHealth Health() const override { return WebHealth(); }
  Status Trigger() override {
    ++triggers;
    return Status::Ok();
  }
  void SetFreeRun(uint16_t rate_dhz) override { free_run = rate_dhz; }
  Status RecordNext(int pairs) override {
    recorded += pairs;
    return Status::Ok();
  }
  void ClearFault() override { ++clears; }
  Result<bool> ApplySetting(ConfigKeyId key, const FwConfig& config) override {
    ++applied;
    return key == ConfigKeyId::budget_ms;
  }
  // Written on the server thread, read by the test after the answer: atomics, since the
  // sockets that order them are invisible to ThreadSanitizer.
  std::atomic<int> triggers{0}, recorded{0}, clears{0}, applied{0}, free_run{-1};
};

struct HttpReply {
  int status = 0;
  std::string headers, body;
};

// One request on a new connection; the whole answer (the server closes it).
HttpReply Send(uint16_t port, const std::string& request) {
  HttpReply reply;
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0) {
    close(fd);
    return reply;
  }
  size_t sent = 0;
  while (sent < request.size()) {
    const ssize_t n = send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;  // the server may refuse before reading everything
    sent += size_t(n);
  }
  std::string text;
  char buf[4096];
  ssize_t n;
  while ((n = recv(fd, buf, sizeof(buf), 0)) > 0) text.append(buf, size_t(n));
  close(fd);
  if (text.compare(0, 9, "HTTP/1.1 ") == 0) reply.status = std::atoi(text.c_str() + 9);
  const size_t split = text.find("\r\n\r\n");
  reply.headers = text.substr(0, split);
  if (split != std::string::npos) reply.body = text.substr(split + 4);
  return reply;
}

std::string Request(const std::string& method, const std::string& path,
                    const std::string& extra_headers = "", const std::string& body = "") {
  return method + " " + path + " HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n" +
         extra_headers + "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body;
}

class WebAppTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::ofstream(config_path_) << "backend = sim  # the simulator\nbudget_ms = 1000\n";
    ASSERT_TRUE(auth_.Configure("secret", "").ok());
    ASSERT_TRUE(snapshot_.Init(RigidTransform()).ok());
    FwConfig running;  // what the file above gives
    running.backend = Backend::kSim;
    running.camera = CameraSource::kSim;
    settings_ = std::make_unique<WebSettings>(running, config_path_.c_str());
    record_dir_ = dir_.path() + "/rec";
    mkdir(record_dir_.c_str(), 0755);
    mkdir((record_dir_ + "/00000007").c_str(), 0755);
    std::ofstream(record_dir_ + "/00000007/result.json") << "{\"sequence\": 7}\n";
    std::ofstream(dir_.path() + "/outside.txt") << "not served\n";
    WebAppConfig c;
    c.record_dir = record_dir_.c_str();
    c.output_frame = "camera";
    app_ = std::make_unique<WebApp>(c, &auth_, settings_.get(), &snapshot_, &target_);
    HttpServerConfig sc;
    ASSERT_TRUE(server_.Start(sc, app_.get()).ok());
  }
  void TearDown() override { server_.Stop(); }

  // Logs in: the cookie header and the CSRF header for later requests.
  std::string LoginHeaders() {
    const HttpReply r = Send(server_.port(), Request("POST", "/api/login", "", "secret"));
    EXPECT_EQ(r.status, 200) << r.body;
    const size_t at = r.headers.find("sh_session=");
    EXPECT_NE(at, std::string::npos);
    const std::string session = r.headers.substr(at + 11, kTokenHexChars);
    const size_t csrf_at = r.body.find("\"csrf\":\"");
    EXPECT_NE(csrf_at, std::string::npos);
    const std::string csrf = r.body.substr(csrf_at + 8, kTokenHexChars);
    return "Cookie: sh_session=" + session + "\r\nX-CSRF-Token: " + csrf + "\r\n";
  }

  testing::TempDir dir_{"web_app"};
  std::string config_path_ = dir_.path() + "/fw.conf";
  std::string record_dir_;
  WebAuth auth_;
  LiveSnapshot snapshot_;
  std::unique_ptr<WebSettings> settings_;
  FakeTarget target_;
  std::unique_ptr<WebApp> app_;
  HttpServer server_;
};

TEST_F(WebAppTest, ServesThePageAndItsStatus) {
  const HttpReply page = Send(server_.port(), Request("GET", "/"));
  EXPECT_EQ(page.status, 200);
  EXPECT_NE(page.body.find("<button id=\"trigger\""), std::string::npos);
  EXPECT_NE(page.headers.find("Content-Security-Policy: default-src 'self'"), std::string::npos);
  const HttpReply status = Send(server_.port(), Request("GET", "/api/status"));
  EXPECT_EQ(status.status, 200);
  EXPECT_NE(status.body.find("\"logged_in\":false"), std::string::npos) << status.body;
}

TEST_F(WebAppTest, ActionsWithoutLoginAreRefusedAndDoNothing) {
  for (const char* path : {"/api/trigger", "/api/continuous?rate_dhz=10", "/api/record?pairs=1",
                           "/api/clear-fault", "/api/settings", "/api/settings/save"}) {
    const HttpReply r = Send(server_.port(), Request("POST", path, "", "budget_ms = 500\n"));
    EXPECT_EQ(r.status, 403) << path;
  }
  EXPECT_EQ(target_.triggers + target_.recorded + target_.clears + target_.applied, 0);
  EXPECT_EQ(target_.free_run, -1);
  std::ifstream in(config_path_);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), "backend = sim  # the simulator\nbudget_ms = 1000\n");
}

TEST_F(WebAppTest, SessionWithoutCsrfTokenIsRefused) {
  std::string headers = LoginHeaders();
  headers = headers.substr(0, headers.find("X-CSRF-Token"));
  EXPECT_EQ(Send(server_.port(), Request("POST", "/api/trigger", headers)).status, 403);
  EXPECT_EQ(target_.triggers, 0);
}

TEST_F(WebAppTest, LoggedInActionsReachTheFirmware) {
  const std::string h = LoginHeaders();
  EXPECT_EQ(Send(server_.port(), Request("POST", "/api/trigger", h)).status, 200);
  EXPECT_EQ(Send(server_.port(), Request("POST", "/api/continuous?rate_dhz=25", h)).status, 200);
  EXPECT_EQ(Send(server_.port(), Request("POST", "/api/record?pairs=3", h)).status, 200);
  EXPECT_EQ(Send(server_.port(), Request("POST", "/api/clear-fault", h)).status, 200);
  EXPECT_EQ(target_.triggers, 1);
  EXPECT_EQ(target_.free_run, 25);
  EXPECT_EQ(target_.recorded, 3);
  EXPECT_EQ(target_.clears, 1);
  // Out of range: refused before the firmware sees it.
  EXPECT_EQ(Send(server_.port(), Request("POST", "/api/record?pairs=0", h)).status, 400);
  EXPECT_EQ(Send(server_.port(), Request("POST", "/api/continuous?rate_dhz=x", h)).status, 400);
  EXPECT_EQ(target_.recorded, 3);
}

TEST_F(WebAppTest, GetCannotChangeAnything) {
  const std::string h = LoginHeaders();
  EXPECT_EQ(Send(server_.port(), Request("GET", "/api/trigger", h)).status, 404);
  EXPECT_EQ(Send(server_.port(), Request("PUT", "/api/trigger", h)).status, 405);
  EXPECT_EQ(target_.triggers, 0);
}

TEST_F(WebAppTest, NoPathLeavesTheServedSet) {
  for (const char* path : {"/../outside.txt", "/..%2foutside.txt", "/api/../../etc/passwd",
                           "/style.css/../../outside.txt", "//etc/passwd"}) {
    const HttpReply r = Send(server_.port(), Request("GET", path));
    EXPECT_EQ(r.status, 404) << path;
    EXPECT_EQ(r.body.find("not served"), std::string::npos) << path;
  }
  for (const char* pair : {"../outside.txt", "..%2F..%2Fetc", "0000007", "000000077", "/tmp"}) {
    const HttpReply r =
        Send(server_.port(), Request("GET", std::string("/api/recordings?pair=") + pair));
    EXPECT_EQ(r.status, 400) << pair;
  }
}

TEST_F(WebAppTest, RecordingDownloadsAsTar) {
  const HttpReply list = Send(server_.port(), Request("GET", "/api/recordings"));
  EXPECT_EQ(list.body, "[\"00000007\"]");
  const HttpReply tar = Send(server_.port(), Request("GET", "/api/recordings?pair=00000007"));
  ASSERT_EQ(tar.status, 200);
  ASSERT_EQ(tar.body.size() % 512, 0u);
  EXPECT_EQ(tar.body.substr(0, 20), std::string("00000007/result.json"));
  EXPECT_EQ(tar.body.substr(257, 5), "ustar");
  EXPECT_NE(tar.body.find("{\"sequence\": 7}"), std::string::npos);
}

TEST_F(WebAppTest, OversizedRequestsAreRefused) {
  const std::string h = LoginHeaders();
  const HttpReply body = Send(
      server_.port(), Request("POST", "/api/settings", h, std::string(kMaxBodyBytes + 1, '#')));
  EXPECT_EQ(body.status, 413);
  const HttpReply header = Send(
      server_.port(), Request("GET", "/api/status",
                              "X-Filler: " + std::string(kConnectionMemoryBytes, 'x') + "\r\n"));
  EXPECT_GE(header.status, 400);
  EXPECT_EQ(target_.applied, 0);
}

TEST_F(WebAppTest, SettingsAreValidatedAsInTheFile) {
  const std::string h = LoginHeaders();
  const HttpReply bad =
      Send(server_.port(), Request("POST", "/api/settings", h, "budget_ms = 5\n"));
  EXPECT_EQ(bad.status, 400);
  EXPECT_NE(bad.body.find("line 1: key 'budget_ms': expected an integer in 20..10000 (got '5')"),
            std::string::npos)
      << bad.body;
  const HttpReply locked =
      Send(server_.port(), Request("POST", "/api/settings", h, "http_password = open\n"));
  EXPECT_EQ(locked.status, 409);
  EXPECT_EQ(target_.applied, 0);
  const HttpReply good = Send(
      server_.port(), Request("POST", "/api/settings", h, "budget_ms = 500\nsim_objects = 4\n"));
  EXPECT_EQ(good.status, 200) << good.body;
  EXPECT_NE(good.body.find("budget_ms: applied"), std::string::npos) << good.body;
  EXPECT_NE(good.body.find("sim_objects: at the next start"), std::string::npos) << good.body;
  EXPECT_EQ(Send(server_.port(), Request("POST", "/api/settings/save", h)).status, 200);
  std::ifstream in(config_path_);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), "backend = sim  # the simulator\nbudget_ms = 500\nsim_objects = 4\n");
}

TEST_F(WebAppTest, PasswordIsNeverShown) {
  FwConfig c;
  std::memcpy(c.http_password, "hidden", 7);
  WebSettings settings(c, "");
  EXPECT_EQ(settings.Json().find("hidden"), std::string::npos);
  EXPECT_NE(settings.Json().find("(set)"), std::string::npos);
}

TEST(RewriteConfigText, KeepsCommentsAndAppendsNewKeys) {
  FwConfig c;
  c.budget_ms = 300;
  c.sim_objects = 5;
  ConfigKeySet edited;
  edited.Add(static_cast<size_t>(ConfigKeyId::budget_ms));
  edited.Add(static_cast<size_t>(ConfigKeyId::sim_objects));
  const std::string text = "# head\nbudget_ms = 1000   # per trigger\nnode_id = 3\n";
  EXPECT_EQ(RewriteConfigText(text, c, edited),
            "# head\nbudget_ms = 300  # per trigger\nnode_id = 3\nsim_objects = 5\n");
}

TEST(PairNames, OnlyEightDigits) {
  EXPECT_TRUE(IsPairName("00000000"));
  EXPECT_TRUE(IsPairName("12345678"));
  EXPECT_FALSE(IsPairName("1234567"));
  EXPECT_FALSE(IsPairName("123456789"));
  EXPECT_FALSE(IsPairName("1234567a"));
  EXPECT_FALSE(IsPairName("../12345"));
  EXPECT_FALSE(IsPairName(""));
  EXPECT_FALSE(IsPairName(nullptr));
}

TEST(LiveSnapshot, PublishesWithoutTheHeapAndReducesTheImages) {
  LiveSnapshot snapshot;
  ASSERT_TRUE(snapshot.Init(RigidTransform()).ok());
  std::vector<uint8_t> left(size_t{1280} * 800, 7), right(size_t{1280} * 800, 9);
  hal::StereoFrame frame;
  frame.left = {left.data(), 1280, 800, 1280};
  frame.right = {right.data(), 1280, 800, 1280};
  protocol::ResultSet set;
  set.object_count = 1;
  const uint64_t before = sh::testing::HeapAllocations();
  snapshot.OnResult(set, &frame);
  EXPECT_EQ(sh::testing::HeapAllocations(), before);
  const LiveResult r = snapshot.Result();
  EXPECT_EQ(r.results, 1u);
  EXPECT_EQ(r.full_width[0], 1280);
  LiveImage image;
  ASSERT_TRUE(snapshot.Image(1, &image));
  EXPECT_EQ(image.width, 640);
  EXPECT_EQ(image.height, 400);
  EXPECT_EQ(image.scale, 2);
  EXPECT_EQ(image.pixels[0], 9);
}

TEST(JsonWriter, EscapesText) {
  std::string out;
  AppendJsonString(&out, "a\"b\\c\n\x01\xff", 8);
  EXPECT_EQ(out, "\"a\\\"b\\\\c\\n\\u0001\\ufffd\"");
}

}  // namespace
}  // namespace sh::fw::web
