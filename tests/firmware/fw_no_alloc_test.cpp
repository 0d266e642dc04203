// After boot the firmware allocates nothing: 100+ triggers (CAN and GPIO; 20 under the
// sanitizers, tests/support/workload.hpp) through the whole simulated path (pre-rendered frames,
// SimCamera pairing, recognition, result encoding, the simulated bus), with the CANopen services
// in use (the stream and the PDO answers, SDO uploads expedited and segmented) and every pair
// recorded by the writer thread, while every operator new in this process is counted.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <string>

#include <dirent.h>

#include "firmware/truth_recognition.hpp"
#include "tests/support/counting_allocator.hpp"
#include "tests/support/firmware_doubles.hpp"
#include "tests/support/sim_world_once.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/workload.hpp"
#ifdef STEREOHASH_FW_HAVE_PIPELINE
#include "firmware/pipeline_recognition.hpp"
#include "tests/support/clock_standing_still.hpp"
#endif

namespace sh::testing {
namespace {

TEST(FirmwareNoAlloc, TriggersAfterBootAllocateNothing) {
  static render::SimWorld world;
  render::SimWorldConfig wc;
  wc.models_dir = STEREOHASH_FW_SOURCE_MODELS_DIR;
  wc.scenes = 3;
  wc.objects = 3;
  ASSERT_TRUE(BuildOnce(world, wc));

  PlcBus can;
  hal::SimCanEndpoint* fw = can.fw;
  hal::SimCanEndpoint* plc = can.plc;
  hal::SimGpio gpio;
  hal::SimCamera camera(&world, hal::SimCameraConfig{});
  FileDataSource data("builtin", "", &world.calibration());
#ifdef STEREOHASH_FW_HAVE_PIPELINE
  static Pipeline pipeline;
  PipelineRecognition recognition({&pipeline}, WithClockStandingStill());
  const char* kind = "pipeline";
#else
  TruthRecognition recognition(&world);
  const char* kind = "truth";
#endif
  CoreConfig config;
  config.node_id = 1;
  config.heartbeat_ms = 20;
  config.capture_timeout_ms = 500;
  // Never reached with the pipeline: its clock stands still, since under the sanitizers a frame
  // takes seconds and a budget cut-off would leave sets without objects. The cut-off path's
  // allocations are counted in pipeline_alloc_test.
  config.budget_ms = kTimeBudgetMinMs;
  config.result_mode = canopen::ResultMode::kBoth;
  const sh::testing::TempDir temp("record");
  ASSERT_TRUE(temp.ok());
  const char* record_dir = temp.path().c_str();
  static Recorder recorder;
  RecorderConfig rc;
  rc.directory = record_dir;
  rc.max_pairs = 20;
  CoreDevices devices = SimCoreDevices(fw, &gpio, &camera, &recognition, &data);
  static FirmwareCore core;
  ASSERT_TRUE(recorder.Start(rc, world.calibration(), nullptr, &core).ok());
  devices.recorder = &recorder;
  ASSERT_TRUE(core.Start(config, devices).ok());
  ASSERT_EQ(core.state(), FirmwareState::kReady);

  // Warm-up trigger outside the window (first use of lazily initialised library state).
  ResultAssembler assembler(1);
  // Up to 20 s per set.
  auto wait_set = [&](ResultSet* out) { return WaitResultSet(plc, &assembler, out, 2000); };
  // An SDO upload (0x1018 sub 2: expedited; 0x1008: segmented, two segments) and a PDO-mode
  // request for object 0, each answered before the next trigger.
  auto wait_for = [&](uint32_t id, int first_byte) {
    for (int i = 0; i < 2000; ++i) {
      hal::CanFrame f;
      Result<bool> got = plc->Receive(&f, 10);
      if (got.ok() && *got && f.id == id && (first_byte < 0 || f.data[0] == first_byte)) {
        return true;
      }
    }
    return false;
  };
  int services_answered = 0;
  auto use_services = [&](uint8_t counter) {
    hal::CanFrame sdo;
    sdo.id = 0x601;
    sdo.len = 8;
    sdo.data[0] = 0x40;
    sdo.data[1] = 0x18;
    sdo.data[2] = 0x10;
    sdo.data[3] = 2;
    (void)plc->Send(sdo);
    bool ok = wait_for(0x581, 0x43);
    sdo.data[1] = 0x08;
    sdo.data[3] = 0;
    (void)plc->Send(sdo);
    ok = ok && wait_for(0x581, 0x41);
    hal::CanFrame segment;
    segment.id = 0x601;
    segment.len = 8;
    for (uint8_t toggle = 0; toggle < 2; ++toggle) {
      segment.data[0] = static_cast<uint8_t>(0x60 | toggle << 4);
      (void)plc->Send(segment);
      ok = ok && wait_for(0x581, -1);
    }
    hal::CanFrame request;
    request.id = 0x301;
    request.len = 2;
    request.data[0] = counter;
    (void)plc->Send(request);
    ok = ok && wait_for(0x4C1, -1);
    services_answered += ok;
  };
  static ResultSet set;
  ASSERT_TRUE(plc->Send(TriggerFrame(1, 1)).ok());
  ASSERT_TRUE(wait_set(&set));
  use_services(0);

  constexpr int kTriggers = Repetitions(100, 20);
  int sets = 0, with_objects = 0, ok_status = 0;
  const uint64_t allocations_before = sh::testing::HeapAllocations();
  for (int i = 0; i < kTriggers; ++i) {
    if (i % 4 == 3) {
      gpio.FireTrigger();
    } else {
      ASSERT_TRUE(plc->Send(TriggerFrame(1, uint8_t(2 + i))).ok());
    }
    if (wait_set(&set)) {
      ++sets;
      with_objects += set.object_count > 0;
      ok_status += set.status == ResultStatus::kOk;
    }
    use_services(static_cast<uint8_t>(i + 1));
  }
  const uint64_t allocations = sh::testing::HeapAllocations() - allocations_before;
  core.Stop();
  recorder.Stop();
  const RecorderCounters recorded = recorder.counters();
  int folders = 0;
  if (DIR* d = opendir(record_dir)) {
    while (const dirent* e = readdir(d)) folders += e->d_name[0] == '0';
    closedir(d);
  }
  EXPECT_EQ(services_answered, kTriggers + 1);
  EXPECT_GT(recorded.written, 0u);
  EXPECT_EQ(recorded.written + recorded.dropped, recorded.submitted);
  EXPECT_EQ(recorded.failed, 0u);
  EXPECT_EQ(folders, static_cast<int>(recorded.written < 20 ? recorded.written : 20))
      << "the last record_max pairs are kept";
  EXPECT_EQ(sets, kTriggers);
  EXPECT_EQ(allocations, 0u) << "heap allocations during " << kTriggers
                             << " triggers with recognition = " << kind;
  EXPECT_GT(with_objects, kTriggers / 2);
  std::printf(
      "recognition = %s: %d sets, %d with objects, %d status ok, %llu allocations; recorded %llu "
      "of %llu pairs (%llu dropped: writer behind)\n",
      kind, sets, with_objects, ok_status, static_cast<unsigned long long>(allocations),
      static_cast<unsigned long long>(recorded.written),
      static_cast<unsigned long long>(recorded.submitted),
      static_cast<unsigned long long>(recorded.dropped));
}

}  // namespace
}  // namespace sh::testing
