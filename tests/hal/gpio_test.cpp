#include <gtest/gtest.h>

#include <cstdlib>
#include <thread>

#include "hal/sim/gpio_sim.hpp"
#if STEREOHASH_HAVE_GPIOD
#include "hal/linux/gpiod_gpio.hpp"
#endif

namespace sh::hal {
namespace {

TEST(SimGpioTest, TriggerEdgesArriveInOrderWithTheirTimestamps) {
  SimGpio gpio;
  ASSERT_TRUE(gpio.FireTrigger(1000));
  ASSERT_TRUE(gpio.FireTrigger(2000));
  GpioEdgeEvent ev;
  ASSERT_TRUE(*gpio.WaitTriggerRisingEdge(0, &ev));
  EXPECT_EQ(ev.timestamp_ns, 1000u);
  ASSERT_TRUE(*gpio.WaitTriggerRisingEdge(0, &ev));
  EXPECT_EQ(ev.timestamp_ns, 2000u);
  Result<bool> none = gpio.WaitTriggerRisingEdge(10, &ev);
  ASSERT_TRUE(none.ok());
  EXPECT_FALSE(*none);
}

TEST(SimGpioTest, WaiterWakesOnATriggerFromAnotherThread) {
  SimGpio gpio;
  const uint64_t before = GpioNowNs();
  std::thread fire([&gpio] { gpio.FireTrigger(); });
  GpioEdgeEvent ev;
  Result<bool> r = gpio.WaitTriggerRisingEdge(-1, &ev);
  fire.join();
  ASSERT_TRUE(r.ok() && *r);
  EXPECT_GE(ev.timestamp_ns, before);
}

TEST(SimGpioTest, EdgeQueueOverflowIsCounted) {
  SimGpio gpio;
  for (size_t i = 0; i < kSimGpioTriggerQueueDepth; ++i) EXPECT_TRUE(gpio.FireTrigger(i + 1));
  EXPECT_FALSE(gpio.FireTrigger(99));
  EXPECT_EQ(gpio.triggers_dropped(), 1u);
}

TEST(SimGpioTest, OutputChangesAreRecordedInOrder) {
  SimGpio gpio;
  ASSERT_TRUE(gpio.SetOutput(GpioOutput::kReady, true).ok());
  ASSERT_TRUE(gpio.SetOutput(GpioOutput::kBusy, true).ok());
  ASSERT_TRUE(gpio.SetOutput(GpioOutput::kStrobe, true).ok());
  ASSERT_TRUE(gpio.SetOutput(GpioOutput::kStrobe, false).ok());
  EXPECT_TRUE(gpio.output(GpioOutput::kBusy));
  EXPECT_FALSE(gpio.output(GpioOutput::kStrobe));
  GpioOutputChange log[8];
  ASSERT_EQ(gpio.CopyOutputLog(log, 8), 4u);
  EXPECT_EQ(log[0].output, GpioOutput::kReady);
  EXPECT_EQ(log[2].output, GpioOutput::kStrobe);
  EXPECT_TRUE(log[2].active);
  EXPECT_FALSE(log[3].active);
  for (int i = 1; i < 4; ++i) EXPECT_GE(log[i].timestamp_ns, log[i - 1].timestamp_ns);
  EXPECT_EQ(gpio.SetOutput(static_cast<GpioOutput>(7), true).code(), StatusCode::kInvalidArgument);
}

TEST(SimGpioTest, OutputLogKeepsTheNewestChanges) {
  SimGpio gpio;
  for (size_t i = 0; i < kSimGpioOutputLogDepth + 10; ++i) {
    ASSERT_TRUE(gpio.SetOutput(GpioOutput::kStrobe, i % 2 == 0).ok());
  }
  EXPECT_EQ(gpio.output_log_overwritten(), 10u);
  GpioOutputChange last;
  GpioOutputChange log[kSimGpioOutputLogDepth];
  ASSERT_EQ(gpio.CopyOutputLog(log, kSimGpioOutputLogDepth), kSimGpioOutputLogDepth);
  last = log[kSimGpioOutputLogDepth - 1];
  EXPECT_EQ(last.active, (kSimGpioOutputLogDepth + 9) % 2 == 0);
}

#if STEREOHASH_HAVE_GPIOD
TEST(GpiodGpioTest, MissingChipIsReportedByName) {
  GpiodGpio gpio;
  GpiodConfig config;
  config.chip = "no-such-gpiochip-xyz";
  const Status s = gpio.Open(config);
  EXPECT_EQ(s.code(), StatusCode::kNotFound);
  EXPECT_NE(std::string(s.message()).find("no-such-gpiochip-xyz"), std::string::npos);
  EXPECT_EQ(gpio.SetOutput(GpioOutput::kReady, true).code(), StatusCode::kFailedPrecondition);
  GpioEdgeEvent ev;
  EXPECT_EQ(gpio.WaitTriggerRisingEdge(0, &ev).status().code(), StatusCode::kFailedPrecondition);
}

// Needs a GPIO chip whose lines may be requested, e.g. gpio-sim:
//   modprobe gpio-sim; configure a bank in configfs; STEREOHASH_GPIO_CHIP=gpiochipN
TEST(GpiodGpioTest, DrivesOutputsOnARealChip) {
  const char* chip = std::getenv("STEREOHASH_GPIO_CHIP");
  if (chip == nullptr) {
    GTEST_SKIP() << "no GPIO test chip: set STEREOHASH_GPIO_CHIP to a gpio-sim or spare chip "
                    "(this kernel has no gpio-sim/gpio-mockup)";
  }
  GpiodGpio gpio;
  GpiodConfig config;
  config.chip = chip;
  config.trigger_line = 0;
  config.ready_line = 1;
  config.busy_line = 2;
  config.strobe_line = 3;
  const Status s = gpio.Open(config);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_TRUE(gpio.SetOutput(GpioOutput::kReady, true).ok());
  EXPECT_TRUE(gpio.SetOutput(GpioOutput::kBusy, false).ok());
  GpioEdgeEvent ev;
  Result<bool> r = gpio.WaitTriggerRisingEdge(10, &ev);
  EXPECT_TRUE(r.ok()) << r.status().message();
}
#else
TEST(GpiodGpioTest, NotBuilt) { GTEST_SKIP() << "libgpiod not found at configure time"; }
#endif

}  // namespace
}  // namespace sh::hal
