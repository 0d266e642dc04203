// The CAN health monitor without threads or a bus: sequences of controller states, counters and
// fault bits, and the error conditions and EMCYs each period brings.
#include "firmware/can_health.hpp"

#include <gtest/gtest.h>

#include "firmware/firmware_core.hpp"

namespace sh::fw {
namespace {

using hal::CanBusState;
using protocol::EmcyCode;
using Kind = CanHealthMonitor::Kind;
using Actions = CanHealthMonitor::Actions;

TEST(CanHealth, BusOffIsRaisedOnceWhenTheControllerIsBack) {
  hal::CanStats stats;
  CanHealthMonitor health(stats);
  // While bus-off nothing can be sent: no EMCY, however many periods pass.
  stats.bus_off_events = 1;
  EXPECT_EQ(health.Step(CanBusState::kBusOff, stats, kFaultCanBusOff).count, 0);
  EXPECT_EQ(health.Step(CanBusState::kBusOff, stats, kFaultCanBusOff).count, 0);
  // Back on the bus with the fault still set: the condition with the bus-off count, once.
  Actions a = health.Step(CanBusState::kErrorActive, stats, kFaultCanBusOff);
  ASSERT_EQ(a.count, 1);
  EXPECT_EQ(a.action[0].kind, Kind::kRaise);
  EXPECT_EQ(a.action[0].condition, kFaultCanBusOff);
  EXPECT_EQ(a.action[0].code, EmcyCode::kRecoveredFromBusOff);
  EXPECT_EQ(a.action[0].detail, 1u);
  EXPECT_EQ(health.Step(CanBusState::kErrorActive, stats, kFaultCanBusOff).count, 0);
  // Fault cleared (by clear-fault, which sends the error reset), then a second episode: raised
  // again.
  EXPECT_EQ(health.Step(CanBusState::kErrorActive, stats, 0).count, 0);
  stats.bus_off_events = 2;
  EXPECT_EQ(health.Step(CanBusState::kBusOff, stats, kFaultCanBusOff).count, 0);
  a = health.Step(CanBusState::kErrorActive, stats, kFaultCanBusOff);
  ASSERT_EQ(a.count, 1);
  EXPECT_EQ(a.action[0].detail, 2u);
}

TEST(CanHealth, ErrorPassiveIsAWarningUntilTheControllerIsActiveAgain) {
  const hal::CanStats stats;
  CanHealthMonitor health(stats);
  Actions a = health.Step(CanBusState::kErrorPassive, stats, 0);
  ASSERT_EQ(a.count, 1);
  EXPECT_EQ(a.action[0].kind, Kind::kRaise);
  EXPECT_EQ(a.action[0].condition, kWarningCanErrorPassive);
  EXPECT_EQ(a.action[0].code, EmcyCode::kCanErrorPassive);
  EXPECT_EQ(health.Step(CanBusState::kErrorPassive, stats, 0).count, 0);
  // Warning is not active: still the same episode.
  EXPECT_EQ(health.Step(CanBusState::kErrorWarning, stats, 0).count, 0);
  EXPECT_EQ(health.Step(CanBusState::kErrorPassive, stats, 0).count, 0);
  // Active again: the warning ends, once.
  a = health.Step(CanBusState::kErrorActive, stats, 0);
  ASSERT_EQ(a.count, 1);
  EXPECT_EQ(a.action[0].kind, Kind::kClear);
  EXPECT_EQ(a.action[0].condition, kWarningCanErrorPassive);
  EXPECT_EQ(health.Step(CanBusState::kErrorActive, stats, 0).count, 0);
  EXPECT_EQ(health.Step(CanBusState::kErrorPassive, stats, 0).count, 1);
}

TEST(CanHealth, NoClearWithoutAPassiveEpisode) {
  const hal::CanStats stats;
  CanHealthMonitor health(stats);
  EXPECT_EQ(health.Step(CanBusState::kErrorActive, stats, 0).count, 0);
  EXPECT_EQ(health.Step(CanBusState::kErrorWarning, stats, 0).count, 0);
  EXPECT_EQ(health.Step(CanBusState::kErrorActive, stats, 0).count, 0);
}

TEST(CanHealth, DroppedFramesOncePerFaultAndNotWhileBusOff) {
  hal::CanStats stats;
  CanHealthMonitor health(stats);
  stats.tx_dropped_queue_full = 7;
  EXPECT_EQ(health.Step(CanBusState::kBusOff, stats, kFaultCanTxDropped).count, 0);
  Actions a = health.Step(CanBusState::kErrorActive, stats, kFaultCanTxDropped);
  ASSERT_EQ(a.count, 1);
  EXPECT_EQ(a.action[0].kind, Kind::kRaise);
  EXPECT_EQ(a.action[0].condition, kFaultCanTxDropped);
  EXPECT_EQ(a.action[0].code, EmcyCode::kCommunication);
  EXPECT_EQ(a.action[0].detail, 7u);
  EXPECT_EQ(health.Step(CanBusState::kErrorActive, stats, kFaultCanTxDropped).count, 0);
  EXPECT_EQ(health.Step(CanBusState::kErrorActive, stats, 0).count, 0);
  EXPECT_EQ(health.Step(CanBusState::kErrorActive, stats, kFaultCanTxDropped).count, 1);
}

TEST(CanHealth, OverrunIsAnEventWithTheFramesLostSinceTheLastPeriod) {
  hal::CanStats stats;
  stats.rx_dropped_overflow = 10;  // before the monitor started: not reported
  CanHealthMonitor health(stats);
  EXPECT_EQ(health.Step(CanBusState::kErrorActive, stats, 0).count, 0);
  stats.rx_dropped_overflow = 13;
  const Actions a = health.Step(CanBusState::kErrorActive, stats, 0);
  ASSERT_EQ(a.count, 1);
  EXPECT_EQ(a.action[0].kind, Kind::kEvent);
  EXPECT_EQ(a.action[0].code, EmcyCode::kCanOverrun);
  EXPECT_EQ(a.action[0].detail, 3u);
  EXPECT_EQ(health.Step(CanBusState::kErrorActive, stats, 0).count, 0);
}

TEST(CanHealth, CountersSaturateInTheDetail) {
  hal::CanStats stats;
  CanHealthMonitor health(stats);
  stats.rx_dropped_overflow = uint64_t{1} << 40;
  const Actions a = health.Step(CanBusState::kErrorActive, stats, 0);
  ASSERT_EQ(a.count, 1);
  EXPECT_EQ(a.action[0].detail, 0xFFFFFFFFu);
}

TEST(CanHealth, EverythingAtOnceComesInOrder) {
  hal::CanStats stats;
  CanHealthMonitor health(stats);
  stats.bus_off_events = 1;
  stats.tx_dropped_queue_full = 2;
  stats.rx_dropped_overflow = 5;
  const Actions first =
      health.Step(CanBusState::kBusOff, stats, kFaultCanBusOff | kFaultCanTxDropped);
  ASSERT_EQ(first.count, 1);  // only the overrun: nothing else can be said while bus-off
  EXPECT_EQ(first.action[0].code, EmcyCode::kCanOverrun);
  const Actions a =
      health.Step(CanBusState::kErrorPassive, stats, kFaultCanBusOff | kFaultCanTxDropped);
  ASSERT_EQ(a.count, 3);
  EXPECT_EQ(a.action[0].code, EmcyCode::kRecoveredFromBusOff);
  EXPECT_EQ(a.action[1].code, EmcyCode::kCanErrorPassive);
  EXPECT_EQ(a.action[2].code, EmcyCode::kCommunication);
}

}  // namespace
}  // namespace sh::fw
