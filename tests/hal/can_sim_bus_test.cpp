#include <gtest/gtest.h>

#include <thread>

#include "hal/sim/can_sim_bus.hpp"

namespace sh::hal {
namespace {

CanFrame Frame(uint32_t id, uint8_t first_byte = 0) {
  CanFrame f;
  f.id = id;
  f.len = 1;
  f.data[0] = first_byte;
  return f;
}

class SimCanBusTest : public ::testing::Test {
 protected:
  SimCanEndpoint* Add(SimCanEndpointConfig config = {}) {
    Result<SimCanEndpoint*> e = bus_.AddEndpoint(config);
    EXPECT_TRUE(e.ok()) << e.status().message();
    return e.ok() ? *e : nullptr;
  }
  SimCanBus bus_;
};

TEST_F(SimCanBusTest, DeliversToEveryOtherEndpointButNotTheSender) {
  SimCanEndpoint* a = Add();
  SimCanEndpoint* b = Add();
  SimCanEndpoint* c = Add();
  ASSERT_TRUE(a->Send(Frame(0x181, 7)).ok());
  CanFrame got;
  for (SimCanEndpoint* e : {b, c}) {
    Result<bool> r = e->Receive(&got, 1000);
    ASSERT_TRUE(r.ok() && *r);
    EXPECT_EQ(got.id, 0x181u);
    EXPECT_EQ(got.data[0], 7);
    EXPECT_NE(got.timestamp_us, 0u);
  }
  Result<bool> own = a->Receive(&got, 0);
  ASSERT_TRUE(own.ok());
  EXPECT_FALSE(*own);
  EXPECT_EQ(a->stats().tx_frames, 1u);
  EXPECT_EQ(b->stats().rx_frames, 1u);
  EXPECT_EQ(bus_.frames_on_bus(), 1u);
}

TEST_F(SimCanBusTest, FiltersAcceptOnlyListedIds) {
  SimCanEndpoint* a = Add();
  SimCanEndpointConfig filtered;
  filtered.filter_ids[0] = 0x201;
  filtered.filter_ids[1] = 0x000;
  filtered.filter_count = 2;
  SimCanEndpoint* b = Add(filtered);
  ASSERT_TRUE(a->Send(Frame(0x181)).ok());
  ASSERT_TRUE(a->Send(Frame(0x201)).ok());
  ASSERT_TRUE(a->Send(Frame(0x000)).ok());
  CanFrame got;
  ASSERT_TRUE(*b->Receive(&got, 100));
  EXPECT_EQ(got.id, 0x201u);
  ASSERT_TRUE(*b->Receive(&got, 100));
  EXPECT_EQ(got.id, 0x000u);
  EXPECT_FALSE(*b->Receive(&got, 0));
}

TEST_F(SimCanBusTest, FullReceiveQueueDropsAndCounts) {
  SimCanEndpoint* a = Add();
  SimCanEndpoint* b = Add();
  for (size_t i = 0; i < kSimCanQueueDepth + 3; ++i) {
    ASSERT_TRUE(a->Send(Frame(0x100, static_cast<uint8_t>(i))).ok());
  }
  EXPECT_EQ(b->stats().rx_dropped_overflow, 3u);
  CanFrame got;
  ASSERT_TRUE(*b->Receive(&got, 0));
  EXPECT_EQ(got.data[0], 0);  // the oldest frames are kept, the newest dropped
}

TEST_F(SimCanBusTest, ConfiguredQueueDepthBoundsTheRingAndItsMemory) {
  SimCanEndpoint* a = Add();
  SimCanEndpointConfig small;
  small.queue_depth = 7;
  SimCanEndpoint* b = Add(small);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->queue_depth(), 7u);
  EXPECT_EQ(SimCanEndpoint::QueueBytes(7), 7 * sizeof(CanFrame));
  EXPECT_LT(SimCanEndpoint::QueueBytes(7), SimCanEndpoint::QueueBytes(kSimCanQueueDepth));
  for (uint8_t i = 0; i < 10; ++i) ASSERT_TRUE(a->Send(Frame(0x100, i)).ok());
  EXPECT_EQ(b->stats().rx_dropped_overflow, 3u);
  CanFrame got;
  for (uint8_t i = 0; i < 7; ++i) {
    ASSERT_TRUE(*b->Receive(&got, 0));
    EXPECT_EQ(got.data[0], i);
  }
  EXPECT_FALSE(*b->Receive(&got, 0));
  // The ring wraps: the freed places take new frames.
  for (uint8_t i = 0; i < 7; ++i) ASSERT_TRUE(a->Send(Frame(0x100, uint8_t(20 + i))).ok());
  EXPECT_EQ(b->stats().rx_dropped_overflow, 3u);
  for (uint8_t i = 0; i < 7; ++i) {
    ASSERT_TRUE(*b->Receive(&got, 0));
    EXPECT_EQ(got.data[0], 20 + i);
  }
  SimCanEndpointConfig too_deep;
  too_deep.queue_depth = kSimCanMaxQueueDepth + 1;
  EXPECT_EQ(bus_.AddEndpoint(too_deep).status().code(), StatusCode::kOutOfRange);
}

TEST_F(SimCanBusTest, RejectsInvalidFrames) {
  SimCanEndpoint* a = Add();
  CanFrame f = Frame(0x800);
  EXPECT_EQ(a->Send(f).code(), StatusCode::kInvalidArgument);
  f = Frame(0x100);
  f.len = 9;
  EXPECT_EQ(a->Send(f).code(), StatusCode::kInvalidArgument);
  f = Frame(0x100);
  f.error = true;
  EXPECT_EQ(a->Send(f).code(), StatusCode::kInvalidArgument);
}

TEST_F(SimCanBusTest, BusOffBlocksSendingUntilRestart) {
  SimCanEndpointConfig config;
  config.deliver_error_frames = true;
  SimCanEndpoint* fw = Add(config);
  SimCanEndpoint* peer = Add();
  bus_.InjectBusOff(fw);
  EXPECT_EQ(fw->state(), CanBusState::kBusOff);
  const Status s = fw->Send(Frame(0x181));
  EXPECT_EQ(s.code(), StatusCode::kUnavailable);
  EXPECT_NE(std::string(s.message()).find("bus-off"), std::string::npos) << s.message();
  CanFrame got;
  EXPECT_FALSE(*peer->Receive(&got, 0));
  ASSERT_TRUE(*fw->Receive(&got, 0));
  EXPECT_TRUE(got.error);
  EXPECT_EQ(got.id, 0x40u);  // CAN_ERR_BUSOFF

  bus_.InjectBusOff(fw);  // already off: no second event
  EXPECT_EQ(fw->stats().bus_off_events, 1u);
  bus_.RecoverFromBusOff(fw);
  EXPECT_EQ(fw->state(), CanBusState::kErrorActive);
  ASSERT_TRUE(*fw->Receive(&got, 0));
  EXPECT_EQ(got.id, 0x100u);  // CAN_ERR_RESTARTED
  EXPECT_TRUE(fw->Send(Frame(0x181)).ok());
  EXPECT_TRUE(*peer->Receive(&got, 100));
  EXPECT_EQ(fw->stats().error_frames, 2u);
}

TEST_F(SimCanBusTest, FullTransmitQueueRetriesThenDrops) {
  SimCanEndpointConfig config;
  config.tx_retry_count = 4;
  SimCanEndpoint* fw = Add(config);
  SimCanEndpoint* peer = Add();
  bus_.InjectTxQueueFull(fw, 3);  // clears within the retries
  EXPECT_TRUE(fw->Send(Frame(0x181)).ok());
  EXPECT_EQ(fw->stats().tx_retries, 3u);
  EXPECT_EQ(fw->stats().tx_dropped_queue_full, 0u);

  bus_.InjectTxQueueFull(fw, 100);  // stays full
  const Status s = fw->Send(Frame(0x182));
  EXPECT_EQ(s.code(), StatusCode::kResourceExhausted);
  EXPECT_EQ(fw->stats().tx_retries, 7u);
  EXPECT_EQ(fw->stats().tx_dropped_queue_full, 1u);
  CanFrame got;
  ASSERT_TRUE(*peer->Receive(&got, 0));
  EXPECT_EQ(got.id, 0x181u);
  EXPECT_FALSE(*peer->Receive(&got, 0));
}

TEST_F(SimCanBusTest, ErrorStateChangesAreReported) {
  SimCanEndpointConfig config;
  config.deliver_error_frames = true;
  SimCanEndpoint* fw = Add(config);
  bus_.InjectErrorState(fw, CanBusState::kErrorPassive);
  EXPECT_EQ(fw->state(), CanBusState::kErrorPassive);
  EXPECT_TRUE(fw->Send(Frame(0x181)).ok());  // error-passive nodes still transmit
  CanFrame got;
  ASSERT_TRUE(*fw->Receive(&got, 0));
  EXPECT_TRUE(got.error);
  EXPECT_EQ(got.data[1] & 0x30, 0x30);
}

TEST_F(SimCanBusTest, ReceiveWakesUpOnAFrameFromAnotherThread) {
  SimCanEndpoint* a = Add();
  SimCanEndpoint* b = Add();
  std::thread sender([a] { EXPECT_TRUE(a->Send(Frame(0x123, 9)).ok()); });
  CanFrame got;
  Result<bool> r = b->Receive(&got, -1);
  sender.join();
  ASSERT_TRUE(r.ok() && *r);
  EXPECT_EQ(got.data[0], 9);
}

TEST_F(SimCanBusTest, EndpointSlotsAreBounded) {
  for (size_t i = 0; i < kSimCanMaxEndpoints; ++i) Add();
  Result<SimCanEndpoint*> extra = bus_.AddEndpoint({});
  EXPECT_EQ(extra.status().code(), StatusCode::kResourceExhausted);
}

}  // namespace
}  // namespace sh::hal
