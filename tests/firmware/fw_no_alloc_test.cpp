// After boot the firmware allocates nothing: 100+ triggers (CAN and GPIO) through the whole
// simulated path (pre-rendered frames, SimCamera pairing, recognition, result encoding, the
// simulated bus) while every operator new in this process is counted.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "firmware/truth_recognition.hpp"
#include "tests/support/counting_allocator.hpp"
#include "tests/support/firmware_doubles.hpp"
#ifdef STEREOHASH_FW_HAVE_PIPELINE
#include "firmware/pipeline_recognition.hpp"
#endif

namespace sh::testing {
namespace {

TEST(FirmwareNoAlloc, HundredTriggersAfterBootAllocateNothing) {
  static render::SimWorld world;
  render::SimWorldConfig wc;
  wc.models_dir = STEREOHASH_FW_SOURCE_MODELS_DIR;
  wc.scenes = 3;
  wc.objects = 3;
  const Status built = world.Build(wc);
  ASSERT_TRUE(built.ok()) << built.message();

  hal::SimCanBus bus;
  hal::SimCanEndpointConfig fw_config;
  fw_config.filter_ids[0] = kCobNmt;
  fw_config.filter_ids[1] = kCobCommand + 1;
  fw_config.filter_count = 2;
  hal::SimCanEndpoint* fw = *bus.AddEndpoint(fw_config);
  hal::SimCanEndpointConfig plc_config;
  plc_config.name = "plc";
  hal::SimCanEndpoint* plc = *bus.AddEndpoint(plc_config);
  hal::SimGpio gpio;
  hal::SimCamera camera(&world, hal::SimCameraConfig{});
  FileDataSource data("builtin", "", &world.calibration());
#ifdef STEREOHASH_FW_HAVE_PIPELINE
  static Pipeline pipeline;
  PipelineRecognition recognition(&pipeline, PipelineRecognitionConfig{});
  const char* kind = "pipeline";
#else
  TruthRecognition recognition(&world);
  const char* kind = "truth";
#endif
  CoreConfig config;
  config.node_id = 1;
  config.heartbeat_ms = 20;
  config.capture_timeout_ms = 500;
  config.budget_ms = 2000;
  CoreDevices devices;
  devices.can = fw;
  devices.gpio = &gpio;
  devices.camera = &camera;
  devices.recognition = &recognition;
  devices.data = &data;
  FirmwareCore core;
  ASSERT_TRUE(core.Start(config, devices).ok());
  ASSERT_EQ(core.state(), FirmwareState::kReady);

  // Warm-up trigger outside the window (first use of lazily initialised library state).
  ResultAssembler assembler(1);
  auto wait_set = [&](ResultSet* out) {
    for (int i = 0; i < 2000; ++i) {  // up to 20 s per set
      hal::CanFrame f;
      Result<bool> got = plc->Receive(&f, 10);
      if (!got.ok() || !*got) continue;
      Result<bool> done = assembler.Feed(f);
      if (done.ok() && *done) {
        *out = assembler.set();
        return true;
      }
    }
    return false;
  };
  static ResultSet set;
  hal::CanFrame trigger;
  trigger.id = kCobCommand + 1;
  trigger.len = 3;
  trigger.data[0] = 0x01;
  trigger.data[1] = 1;
  ASSERT_TRUE(plc->Send(trigger).ok());
  ASSERT_TRUE(wait_set(&set));

  constexpr int kTriggers = 100;
  int sets = 0, with_objects = 0, ok_status = 0;
  const uint64_t allocations_before = sh::testing::HeapAllocations();
  for (int i = 0; i < kTriggers; ++i) {
    if (i % 4 == 3) {
      gpio.FireTrigger();
    } else {
      trigger.data[1] = uint8_t(2 + i);
      plc->Send(trigger);
    }
    if (wait_set(&set)) {
      ++sets;
      with_objects += set.object_count > 0;
      ok_status += set.status == ResultStatus::kOk;
    }
  }
  const uint64_t allocations = sh::testing::HeapAllocations() - allocations_before;
  core.Stop();
  EXPECT_EQ(sets, kTriggers);
  EXPECT_EQ(allocations, 0u) << "heap allocations during " << kTriggers
                             << " triggers with recognition = " << kind;
  EXPECT_GT(with_objects, kTriggers / 2);
  std::printf("recognition = %s: %d sets, %d with objects, %d status ok, %llu allocations\n", kind,
              sets, with_objects, ok_status, static_cast<unsigned long long>(allocations));
}

}  // namespace
}  // namespace sh::testing
