#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/error.h>

#include <cstdlib>
#include <string>

#include "hal/linux/socketcan_bus.hpp"
#include "hal/linux/socketcan_errors.hpp"

namespace sh::hal {
namespace {

// ---------------------------------------------------------------- error frame interpretation
// (pure logic, runs on every kernel)

TEST(SocketCanErrorsTest, BusOffIsCountedOnceAndRestartRecovers) {
  uint8_t data[8] = {};
  CanErrorUpdate u = ApplyCanErrorFrame(CanBusState::kErrorActive, CAN_ERR_BUSOFF, data);
  EXPECT_EQ(u.state, CanBusState::kBusOff);
  EXPECT_TRUE(u.entered_bus_off);
  u = ApplyCanErrorFrame(CanBusState::kBusOff, CAN_ERR_BUSOFF, data);
  EXPECT_FALSE(u.entered_bus_off);
  u = ApplyCanErrorFrame(CanBusState::kBusOff, CAN_ERR_RESTARTED, data);
  EXPECT_EQ(u.state, CanBusState::kErrorActive);
  EXPECT_TRUE(u.restarted);
}

TEST(SocketCanErrorsTest, ControllerLevelsMapToFaultConfinementStates) {
  uint8_t data[8] = {};
  data[1] = CAN_ERR_CRTL_TX_WARNING;
  EXPECT_EQ(ApplyCanErrorFrame(CanBusState::kErrorActive, CAN_ERR_CRTL, data).state,
            CanBusState::kErrorWarning);
  data[1] = CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_WARNING;
  EXPECT_EQ(ApplyCanErrorFrame(CanBusState::kErrorWarning, CAN_ERR_CRTL, data).state,
            CanBusState::kErrorPassive);
  data[1] = CAN_ERR_CRTL_ACTIVE;
  EXPECT_EQ(ApplyCanErrorFrame(CanBusState::kErrorPassive, CAN_ERR_CRTL, data).state,
            CanBusState::kErrorActive);
  data[1] = CAN_ERR_CRTL_RX_OVERFLOW;
  const CanErrorUpdate u = ApplyCanErrorFrame(CanBusState::kErrorActive, CAN_ERR_CRTL, data);
  EXPECT_TRUE(u.controller_overflow);
  EXPECT_EQ(u.state, CanBusState::kErrorActive);
  // An error class without state information leaves the state alone.
  EXPECT_EQ(ApplyCanErrorFrame(CanBusState::kErrorWarning, CAN_ERR_ACK, data).state,
            CanBusState::kErrorWarning);
}

TEST(SocketCanErrorsTest, SubscribesToTheRequiredErrorClasses) {
  const uint32_t mask = SocketCanErrorMask();
  EXPECT_TRUE(mask & CAN_ERR_BUSOFF);
  EXPECT_TRUE(mask & CAN_ERR_CRTL);
  EXPECT_TRUE(mask & CAN_ERR_RESTARTED);
  EXPECT_FALSE(mask & CAN_ERR_BUSERROR);  // may flood on a broken bus
}

TEST(SocketCanBusTest, RejectsBadConfigurationBeforeTouchingTheKernel) {
  SocketCanBus bus;
  SocketCanConfig config;
  config.interface = "";
  EXPECT_EQ(bus.Open(config).code(), StatusCode::kInvalidArgument);
  config.interface = "an-interface-name-too-long";
  EXPECT_EQ(bus.Open(config).code(), StatusCode::kInvalidArgument);
  config.interface = "can0";
  config.filter_count = kSocketCanMaxFilters + 1;
  EXPECT_EQ(bus.Open(config).code(), StatusCode::kInvalidArgument);
  CanFrame f;
  EXPECT_EQ(bus.Send(f).code(), StatusCode::kFailedPrecondition);
}

// ---------------------------------------------------------------- real sockets (vcan)

// Opens `config` or explains why the test cannot run here.
#define OPEN_OR_SKIP(bus, config)                                                        \
  do {                                                                                   \
    const Status s_ = (bus).Open(config);                                                \
    if (s_.code() == StatusCode::kUnimplemented || s_.code() == StatusCode::kNotFound) { \
      GTEST_SKIP() << "needs a vcan interface (modprobe vcan; ip link add dev "          \
                   << (config).interface << " type vcan; ip link set up "                \
                   << (config).interface << "): " << s_.message();                       \
    }                                                                                    \
    ASSERT_TRUE(s_.ok()) << s_.message();                                                \
  } while (0)

const char* VcanName() {
  const char* env = std::getenv("STEREOHASH_VCAN");
  return env != nullptr ? env : "vcan0";
}

TEST(SocketCanBusTest, ExchangesFramesOverVcan) {
  SocketCanConfig tx_config;
  tx_config.interface = VcanName();
  SocketCanConfig rx_config = tx_config;
  rx_config.filter_ids[0] = 0x201;
  rx_config.filter_count = 1;
  SocketCanBus tx, rx;
  OPEN_OR_SKIP(tx, tx_config);
  OPEN_OR_SKIP(rx, rx_config);

  CanFrame ignored;
  ignored.id = 0x181;
  ignored.len = 1;
  ASSERT_TRUE(tx.Send(ignored).ok());
  CanFrame cmd;
  cmd.id = 0x201;
  cmd.len = 3;
  cmd.data[0] = 1;
  cmd.data[1] = 0x34;
  cmd.data[2] = 0x12;
  ASSERT_TRUE(tx.Send(cmd).ok());
  CanFrame got;
  Result<bool> r = rx.Receive(&got, 1000);
  ASSERT_TRUE(r.ok()) << r.status().message();
  ASSERT_TRUE(*r);
  EXPECT_EQ(got.id, 0x201u);  // 0x181 was filtered out
  EXPECT_EQ(got.len, 3);
  EXPECT_EQ(got.data[1], 0x34);
  EXPECT_NE(got.timestamp_us, 0u);
  EXPECT_EQ(tx.stats().tx_frames, 2u);
  EXPECT_EQ(rx.stats().rx_frames, 1u);
  r = rx.Receive(&got, 0);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(*r);
}

TEST(SocketCanBusTest, ExtendedAndRemoteFramesKeepTheirFlags) {
  SocketCanConfig config;
  config.interface = VcanName();
  config.receive_own_messages = true;
  SocketCanBus bus;
  OPEN_OR_SKIP(bus, config);
  CanFrame f;
  f.id = 0x1ABCDE01;
  f.extended = true;
  f.len = 2;
  ASSERT_TRUE(bus.Send(f).ok());
  CanFrame got;
  Result<bool> r = bus.Receive(&got, 1000);
  ASSERT_TRUE(r.ok() && *r);
  EXPECT_TRUE(got.extended);
  EXPECT_EQ(got.id, f.id);
}

}  // namespace
}  // namespace sh::hal
