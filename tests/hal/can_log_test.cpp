#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>

#include "hal/can_log.hpp"
#include "hal/sim/can_sim_bus.hpp"

namespace sh::hal {
namespace {

CanFrame MakeFrame(uint32_t id, std::initializer_list<uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  for (uint8_t b : bytes) f.data[f.len++] = b;
  f.timestamp_us = 1700000000000001ull;
  return f;
}

TEST(CandumpTest, FormatsTheDocumentedLine) {
  char line[kCandumpLineMax];
  const CanFrame f = MakeFrame(0x181, {1, 2, 3, 4, 5, 6, 7, 8});
  ASSERT_GT(FormatCandumpLine(f, "can0", line, sizeof(line)), 0u);
  EXPECT_STREQ(line, "(1700000000.000001) can0 181#0102030405060708\n");
}

TEST(CandumpTest, RoundTripsEveryFrameKind) {
  CanFrame frames[5];
  frames[0] = MakeFrame(0x7FF, {});
  frames[1] = MakeFrame(0x1ABCDEF0, {0xFF, 0x00, 0x7E});
  frames[1].extended = true;
  frames[2] = MakeFrame(0x123, {});
  frames[2].rtr = true;
  frames[2].len = 4;
  frames[3] = MakeFrame(0x040, {0, 0x10, 0, 0, 0, 0, 0, 0});
  frames[3].error = true;
  frames[4] = MakeFrame(0x000, {0x01, 0x00});
  for (const CanFrame& f : frames) {
    char line[kCandumpLineMax];
    ASSERT_GT(FormatCandumpLine(f, "vcan12", line, sizeof(line)), 0u) << f.id;
    CanFrame back;
    char iface[16];
    ASSERT_TRUE(ParseCandumpLine(line, &back, iface, sizeof(iface)).ok()) << line;
    EXPECT_STREQ(iface, "vcan12");
    EXPECT_EQ(back.id, f.id) << line;
    EXPECT_EQ(back.len, f.len) << line;
    EXPECT_EQ(back.extended, f.extended) << line;
    EXPECT_EQ(back.rtr, f.rtr) << line;
    EXPECT_EQ(back.error, f.error) << line;
    EXPECT_EQ(back.timestamp_us, f.timestamp_us) << line;
    if (!f.rtr) {
      EXPECT_EQ(std::memcmp(back.data, f.data, f.len), 0) << line;
    }
  }
}

TEST(CandumpTest, RejectsMalformedLinesWithAReason) {
  const char* bad[] = {
      "",
      "1700000000.000001 can0 181#01",
      "(1700000000.1) can0 181#01",
      "(1700000000.000001) can0 18#01",
      "(1700000000.000001) can0 181#012",
      "(1700000000.000001) can0 181#010203040506070809",
      "(1700000000.000001) can0 181#01xz",
      "(1700000000.000001) can0",
      "(1700000000.000001) can0 1FF#R9",
  };
  for (const char* line : bad) {
    CanFrame f;
    const Status s = ParseCandumpLine(line, &f, nullptr, 0);
    EXPECT_FALSE(s.ok()) << "'" << line << "'";
    EXPECT_GT(std::strlen(s.message()), 10u) << line;
  }
}

TEST(CandumpTest, FormatFailsCleanlyWhenTheBufferIsTooSmall) {
  char line[20];
  EXPECT_EQ(
      FormatCandumpLine(MakeFrame(0x181, {1, 2, 3, 4, 5, 6, 7, 8}), "can0", line, sizeof(line)),
      0u);
}

TEST(CandumpTest, LoggerRecordsSentAndReceivedFramesOfAnyBackend) {
  SimCanBus bus;
  SimCanEndpointConfig config;
  config.name = "can0";
  Result<SimCanEndpoint*> a = bus.AddEndpoint(config);
  Result<SimCanEndpoint*> b = bus.AddEndpoint(config);
  ASSERT_TRUE(a.ok() && b.ok());
  FILE* log = std::tmpfile();
  ASSERT_NE(log, nullptr);
  CandumpLogger logged(*a, log);
  ASSERT_TRUE(logged.Send(MakeFrame(0x181, {0xAA})).ok());
  ASSERT_TRUE((*b)->Send(MakeFrame(0x201, {0x01, 0x02, 0x00})).ok());
  CanFrame got;
  Result<bool> r = logged.Receive(&got, 1000);
  ASSERT_TRUE(r.ok() && *r);

  std::rewind(log);
  char line[kCandumpLineMax];
  CanFrame parsed;
  ASSERT_NE(std::fgets(line, sizeof(line), log), nullptr);
  ASSERT_TRUE(ParseCandumpLine(line, &parsed, nullptr, 0).ok());
  EXPECT_EQ(parsed.id, 0x181u);
  ASSERT_NE(std::fgets(line, sizeof(line), log), nullptr);
  ASSERT_TRUE(ParseCandumpLine(line, &parsed, nullptr, 0).ok());
  EXPECT_EQ(parsed.id, 0x201u);
  EXPECT_EQ(parsed.len, 3);
  EXPECT_EQ(std::fgets(line, sizeof(line), log), nullptr);
  EXPECT_EQ(logged.write_errors(), 0u);
  std::fclose(log);
}

}  // namespace
}  // namespace sh::hal
