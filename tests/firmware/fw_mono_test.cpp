// The one-camera fallback of the firmware core with the simulator's world and the real
// recognition: the right camera goes silent after three frames, EMCY 0x7300 (one camera) follows
// with the state staying ready, result sets come with the monocular status and poses that match
// the rendered truth, without heap allocation, and a clear-fault returns to stereo once the
// camera is back. While both cameras deliver, the fallback's recogniser serves the stereo
// pipeline's one-image rescue: it adds what stereo missed, is lent again after a right-camera
// fallback and after a model mask change, and is absent without the fallback. Own binary: it
// counts every operator new of the process.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "firmware/pipeline_recognition.hpp"
#include "firmware/truth_recognition.hpp"
#include "recog/mono/aspect.hpp"
#include "set_score.hpp"
#include "tables/aspect_file.hpp"
#include "tests/support/clock_standing_still.hpp"
#include "tests/support/counting_allocator.hpp"
#include "tests/support/firmware_doubles.hpp"
#include "tests/support/sim_world_once.hpp"
#include "tests/support/temp_dir.hpp"
#include "tools/eval/synthetic_scene.hpp"
#include "tools/tablegen/model_set_writer.hpp"

namespace sh::testing {
namespace {

constexpr uint8_t kNodeId = 1;

// The PLC side: result sets, EMCYs and acks from the bus, each kept in arrival order.
class Plc {
 public:
  explicit Plc(hal::SimCanEndpoint* endpoint) : endpoint_(endpoint), assembler_(kNodeId) {
    // Room for every frame of the test, so the PLC side allocates nothing while counting.
    emcys_.reserve(64);
    acks_.reserve(64);
  }

  void Send(std::initializer_list<uint8_t> bytes) {
    ASSERT_TRUE(endpoint_->Send(CommandFrame(kNodeId, bytes)).ok());
  }
  void Trigger(uint16_t request_id) {
    Send({0x01, uint8_t(request_id), uint8_t(request_id >> 8), 0, 0, 0, 0, 0});
  }

  // The next result set (up to 120 s: a frame under qemu takes seconds).
  std::optional<ResultSet> WaitSet() {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (std::chrono::steady_clock::now() < end) {
      if (set_ready_) {
        set_ready_ = false;
        return assembler_.set();
      }
      Poll();
    }
    return std::nullopt;
  }
  std::optional<Emcy> WaitEmcy(uint16_t code) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (true) {
      while (emcy_read_ < emcys_.size()) {
        const Emcy e = emcys_[emcy_read_++];
        if (e.error_code == code) return e;
      }
      if (std::chrono::steady_clock::now() >= end) return std::nullopt;
      Poll();
    }
  }
  std::optional<CommandAck> WaitAck(uint8_t code) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (true) {
      while (ack_read_ < acks_.size()) {
        const CommandAck a = acks_[ack_read_++];
        if (a.command_code == code) return a;
      }
      if (std::chrono::steady_clock::now() >= end) return std::nullopt;
      Poll();
    }
  }

 private:
  void Poll() {
    hal::CanFrame f;
    const Result<bool> got = endpoint_->Receive(&f, 10);
    if (!got.ok() || !*got) return;
    if (f.id == kCobEmcy + kNodeId) {
      const Result<Emcy> e = DecodeEmcy(f, kNodeId);
      if (e.ok()) emcys_.push_back(*e);
      return;
    }
    if (f.id == kCobCommandAck + kNodeId) {
      const Result<CommandAck> a = DecodeCommandAck(f, kNodeId);
      if (a.ok()) acks_.push_back(*a);
      return;
    }
    const Result<bool> done = assembler_.Feed(f);
    if (done.ok() && *done) set_ready_ = true;
  }

  hal::SimCanEndpoint* endpoint_;
  ResultAssembler assembler_;
  bool set_ready_ = false;
  std::vector<Emcy> emcys_;
  size_t emcy_read_ = 0;
  std::vector<CommandAck> acks_;
  size_t ack_read_ = 0;
};

// The set against the world's only scene.
SetScore ScoreSet(const render::SimWorld& world, const TableView& table, const int* table_ids,
                  const ResultSet& set) {
  return ScoreSetOnScene(world, table, table_ids, 0, set);
}

// The firmware core with the simulated world's camera (one scene: the simulator's scenes differ
// in the rig's tilt, and the fallback lays objects onto the table pose it was given, scene 0's),
// the real stereo and monocular pipelines (static: one rig runs at a time) and a PLC.
struct FallbackRig {
  explicit FallbackRig(const hal::SimCameraConfig& camera_config)
      : FallbackRig(camera_config, &World()) {}
  // `world`: the scenes the camera sees (one rig, one table).
  FallbackRig(const hal::SimCameraConfig& camera_config, render::SimWorld* world)
      : world(world),
        fw(*bus.AddEndpoint(hal::SimCanEndpointConfig{})),
        plc(*bus.AddEndpoint(PlcConfig())),
        camera(world, camera_config),
        data(std::make_unique<FileDataSource>("builtin", "", &world->calibration())) {}
  ~FallbackRig() { core.Stop(); }

  static render::SimWorld& World() {
    static render::SimWorld world;
    return OneSceneWorld(&world, 3, render::SimWorldConfig{}.seed);
  }
  // `world` built once: one scene of `objects` plain models placed from `seed`.
  static render::SimWorld& OneSceneWorld(render::SimWorld* world, int objects, uint64_t seed) {
    render::SimWorldConfig wc;
    wc.models_dir = STEREOHASH_FW_SOURCE_MODELS_DIR;
    wc.scenes = 1;
    wc.objects = objects;
    wc.seed = seed;
    EXPECT_TRUE(BuildOnce(*world, wc));
    return *world;
  }

  // table_configured: the rendered table as the cell's table pose; without it the stereo frames
  // estimate the plane, confirm it in `confirm_frames` and carry it (table_estimate = carry).
  // `fallback` false: no monocular pipeline, as the firmware without mono_fallback.
  void Start(bool table_configured = true, uint32_t confirm_frames = 3, bool fallback = true) {
    static Pipeline pipeline;
    static MonoPipeline mono;
    static MonoResult mono_result;
    ObjectRecognizerConfig pc;
    pc.mono_table_known = table_configured;
    pc.left_T_table_at_init = table_configured ? &world->left_T_table() : nullptr;
    pc.table_confirm_frames = confirm_frames;
    pc.now_ns = &ClockStandingStill;
    recognition = std::make_unique<PipelineRecognition>(
        RecognitionPathSet{&pipeline, nullptr, nullptr, fallback ? &mono : nullptr,
                           fallback ? &mono_result : nullptr},
        pc);
    const Result<TableView> table = data->LoadTable();
    ASSERT_TRUE(table.ok());
    MapWorldModelsToIds(*world, ModelSet(&*table, nullptr), table_ids);
    CoreConfig config;
    if (hide_scene_object >= 0) config.model_mask = ~ModelBitOf(hide_scene_object);
    config.node_id = kNodeId;
    config.heartbeat_ms = 100;
    config.capture_timeout_ms = 500;
    config.budget_ms = kTimeBudgetMinMs;  // never reached: the recogniser's clock stands still
    const CoreDevices devices = SimCoreDevices(fw, nullptr, &camera, recognition.get(), data.get());
    ASSERT_TRUE(core.Start(config, devices).ok());
    ASSERT_EQ(core.state(), FirmwareState::kReady);
    ASSERT_EQ(recognition->monocular(), fallback);
  }

  // The model id bit of the scene's object k (after Start).
  uint32_t ModelBitOf(int k) const {
    return 1u << table_ids[world->scene(0).scene.objects[size_t(k)].model_index];
  }

  static hal::SimCanEndpointConfig PlcConfig() {
    hal::SimCanEndpointConfig c;
    c.name = "plc";
    return c;
  }
  render::SimWorld* world;
  hal::SimCanBus bus;
  hal::SimCanEndpoint* fw;

  Plc plc;

  hal::SimCamera camera;

  std::unique_ptr<FileDataSource> data;
  std::unique_ptr<PipelineRecognition> recognition;
  int table_ids[render::kMaxWorldModels] = {};
  // When set before Start: the model of this scene object is left out of the mask at boot, so
  // the stereo search cannot find it and its corners stay free for the one-image rescue.
  int hide_scene_object = -1;
  FirmwareCore core;
};

// A model set as tables with an ASPECTS_2D section gives the fallback its aspect table (mapped
// from the set, not the linked-in one); a set without one leaves the linked-in table.
TEST(FirmwareMonocular, AModelSetsAspectSectionReplacesTheLinkedInTable) {
  const Result<std::vector<uint8_t>> with =
      BuildModelSet({{uint32_t(SectionKind::kHash3d),
                      static_cast<const uint8_t*>(DefaultTableBlob()), DefaultTableBlobSize()},
                     {uint32_t(SectionKind::kAspects2d),
                      static_cast<const uint8_t*>(DefaultAspectBlob()), DefaultAspectBlobSize()}});
  const Result<std::vector<uint8_t>> without =
      BuildModelSet({{uint32_t(SectionKind::kHash3d),
                      static_cast<const uint8_t*>(DefaultTableBlob()), DefaultTableBlobSize()}});
  ASSERT_TRUE(with.ok() && without.ok());
  const sh::testing::TempDir temp("mono_set");
  ASSERT_TRUE(temp.ok());
  const char* dir = temp.path().c_str();
  const std::string with_path = std::string(dir) + "/with.bin";
  const std::string without_path = std::string(dir) + "/without.bin";
  for (const auto& [path, bytes] :
       {std::make_pair(with_path, *with), std::make_pair(without_path, *without)}) {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    ASSERT_EQ(std::fwrite(bytes.data(), 1, bytes.size(), f), bytes.size());
    std::fclose(f);
  }
  static Pipeline pipeline;
  static MonoPipeline mono;
  static MonoResult mono_result;
  const Result<TableView> table = OpenDefaultTable();
  ASSERT_TRUE(table.ok());
  for (const std::string& path : {with_path, without_path}) {
    ObjectRecognizerConfig pc;
    pc.aspects_file = path.c_str();
    PipelineRecognition recognition({&pipeline, nullptr, nullptr, &mono, &mono_result}, pc);
    const Status s =
        recognition.Init(FallbackRig::World().calibration(), ModelSet(&*table, nullptr), 0x3F);
    ASSERT_TRUE(s.ok()) << s.message();
    const bool linked_in = static_cast<const void*>(&recognition.recognizer().aspects().header()) ==
                           DefaultAspectBlob();
    EXPECT_EQ(linked_in, path == without_path) << path;
    EXPECT_EQ(recognition.recognizer().aspects().aspect_count(),
              OpenDefaultAspectTable()->aspect_count());
  }
}

TEST(FirmwareMonocular, RightCameraSilentThenMonocularSetsThenStereoAfterClearFault) {
  hal::SimCameraConfig cc;
  cc.right_stop_after = 3;  // frames 0..2 paired, then the right camera is silent ...
  cc.fault_starts = 1;      // ... until the firmware restarts the camera
  FallbackRig rig(cc);
  rig.Start();
  const render::SimWorld& world = FallbackRig::World();
  Plc& plc = rig.plc;
  FirmwareCore& core = rig.core;
  const FileDataSource& data = *rig.data;
  const int* table_ids = rig.table_ids;

  uint16_t request = 1;
  for (int i = 0; i < 3; ++i) {  // both cameras deliver
    plc.Trigger(request++);
    const std::optional<ResultSet> s = plc.WaitSet();
    ASSERT_TRUE(s);
    EXPECT_EQ(s->status, ResultStatus::kOk);
  }

  // The right camera is silent: the warning, then this very trigger answered from the left one.
  plc.Trigger(request++);
  const std::optional<ResultSet> first_mono = plc.WaitSet();
  ASSERT_TRUE(first_mono);
  EXPECT_EQ(first_mono->status, ResultStatus::kMonocular);
  const std::optional<Emcy> e = plc.WaitEmcy(uint16_t(EmcyCode::kSensor));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->detail >> 24, kSensorOneCamera >> 24);
  EXPECT_EQ((e->detail >> 16) & 0xFF, 1u) << "the right camera failed";
  EXPECT_NE(e->state, FirmwareState::kFault) << "a warning: triggers are still answered";
  EXPECT_NE(e->error_register, 0);
  EXPECT_EQ(core.capture_mode(), hal::CaptureMode::kLeftOnly);

  constexpr int kSets = 4;
  int truth_objects = 0, correct = 0, false_alarms = 0;
  const uint64_t allocations_before = HeapAllocations();
  for (int i = 0; i < kSets; ++i) {
    plc.Trigger(request++);
    const std::optional<ResultSet> s = plc.WaitSet();
    ASSERT_TRUE(s);
    EXPECT_EQ(s->status, ResultStatus::kMonocular);
    const SetScore c = ScoreSet(world, data.table(), table_ids, *s);
    truth_objects += int(world.scene(0).scene.objects.size());
    correct += c.correct;
    false_alarms += c.false_alarms;
  }
  const uint64_t allocations = HeapAllocations() - allocations_before;
  std::printf(
      "monocular sets: %d of %d truth objects within 5 mm / 5 deg, %d false, %llu "
      "allocations\n",
      correct, truth_objects, false_alarms, static_cast<unsigned long long>(allocations));
  EXPECT_EQ(allocations, 0u) << "heap allocations in " << kSets << " monocular triggers";
  EXPECT_GE(correct, truth_objects / 2);
  EXPECT_EQ(false_alarms, 0);

  // Clear-fault restarts the camera in stereo; the right camera is back: ack 0, error reset.
  plc.Send({0x04, 0, 0, 0, 0, 0, 0, 0});
  const std::optional<CommandAck> ack = plc.WaitAck(0x04);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, 0);
  const std::optional<Emcy> reset = plc.WaitEmcy(uint16_t(EmcyCode::kNoError));
  ASSERT_TRUE(reset);
  EXPECT_EQ(reset->error_register, 0);
  EXPECT_EQ(core.capture_mode(), hal::CaptureMode::kStereo);
  plc.Trigger(request++);
  const std::optional<ResultSet> stereo = plc.WaitSet();
  ASSERT_TRUE(stereo);
  EXPECT_EQ(stereo->status, ResultStatus::kOk);
  const SetScore c = ScoreSet(world, data.table(), table_ids, *stereo);
  EXPECT_GE(c.correct, 1);
}

// Without a table pose the fallback lays the objects onto the plane the stereo frames confirmed
// and carried before the right camera went silent: millimetre poses, as with a configured table.
TEST(FirmwareMonocular, WithoutATablePoseTheFallbackUsesTheCarriedPlane) {
  hal::SimCameraConfig cc;
  cc.right_stop_after = 4;  // frames 0..3 paired: two estimates confirm the plane, two carry it
  FallbackRig rig(cc);
  rig.Start(/*table_configured=*/false, /*confirm_frames=*/2);
  uint16_t request = 1;
  std::optional<ResultSet> s;
  for (int i = 0; i < 4; ++i) {
    rig.plc.Trigger(request++);
    s = rig.plc.WaitSet();
    ASSERT_TRUE(s);
    EXPECT_EQ(s->status, ResultStatus::kOk);
  }

  int truth_objects = 0, correct = 0, false_alarms = 0;
  for (int i = 0; i < 3; ++i) {
    rig.plc.Trigger(request++);
    s = rig.plc.WaitSet();
    ASSERT_TRUE(s);
    EXPECT_EQ(s->status, ResultStatus::kMonocular);
    const SetScore c = ScoreSet(FallbackRig::World(), rig.data->table(), rig.table_ids, *s);
    truth_objects += int(FallbackRig::World().scene(0).scene.objects.size());
    correct += c.correct;
    false_alarms += c.false_alarms;
  }
  EXPECT_TRUE(rig.recognition->recognizer().mono_on_carried_plane());
  std::printf("monocular sets on the carried plane: %d of %d within 5 mm / 5 deg, %d false\n",
              correct, truth_objects, false_alarms);
  EXPECT_GE(correct, truth_objects / 2);
  EXPECT_EQ(false_alarms, 0);
}

TEST(FirmwareMonocular, ClearFaultWhileTheCameraIsStillSilentStaysMonocular) {
  hal::SimCameraConfig cc;
  cc.right_stop_after = 0;  // the right camera never delivers, after any restart
  FallbackRig rig(cc);
  rig.Start();
  rig.plc.Trigger(1);
  std::optional<ResultSet> s = rig.plc.WaitSet();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->status, ResultStatus::kMonocular);
  ASSERT_TRUE(rig.plc.WaitEmcy(uint16_t(EmcyCode::kSensor)));

  // Stereo is tried and fails: refused (not possible), back to the left camera alone.
  rig.plc.Send({0x04, 0, 0, 0, 0, 0, 0, 0});
  const std::optional<CommandAck> ack = rig.plc.WaitAck(0x04);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, uint8_t(StatusCode::kFailedPrecondition));
  EXPECT_EQ(rig.core.capture_mode(), hal::CaptureMode::kLeftOnly);
  EXPECT_EQ(rig.core.state(), FirmwareState::kReady);
  rig.plc.Trigger(2);
  s = rig.plc.WaitSet();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->request_id, 2);
  EXPECT_EQ(s->status, ResultStatus::kMonocular);
  const SetScore c = ScoreSet(FallbackRig::World(), rig.data->table(), rig.table_ids, *s);
  EXPECT_EQ(c.false_alarms, 0);
}

// Without the fallback (mono_fallback = false: no monocular pipeline allocated) a silent camera
// is the capture fault, and the cameras stay in stereo.
TEST(FirmwareMonocular, WithoutTheFallbackASilentCameraIsTheCaptureFault) {
  hal::SimCameraConfig cc;
  cc.right_stop_after = 0;  // the right camera never delivers
  FallbackRig rig(cc);
  rig.Start(/*table_configured=*/true, /*confirm_frames=*/3, /*fallback=*/false);
  rig.plc.Trigger(1);
  const std::optional<ResultSet> s = rig.plc.WaitSet();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->status, ResultStatus::kImageError);
  const std::optional<Emcy> e = rig.plc.WaitEmcy(uint16_t(EmcyCode::kSensor));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->detail >> 24, kSensorCaptureFailed >> 24);
  EXPECT_EQ(e->state, FirmwareState::kFault);
  EXPECT_EQ(rig.core.capture_mode(), hal::CaptureMode::kStereo);
}

// A board that boots with one camera not connected starts on the other one: the one-camera
// warning naming the missing side, READY, monocular sets; clear-fault cannot bring stereo back
// while the camera is still missing.
TEST(FirmwareMonocular, BootWithOneCameraMissingStartsOnTheOther) {
  for (const hal::StereoSide missing : {hal::StereoSide::kRight, hal::StereoSide::kLeft}) {
    SCOPED_TRACE(hal::StereoSideName(missing));
    hal::SimCameraConfig cc;
    (missing == hal::StereoSide::kRight ? cc.right_absent : cc.left_absent) = true;
    FallbackRig rig(cc);
    rig.Start();  // READY: a warning, not the camera fault
    const hal::CaptureMode working = missing == hal::StereoSide::kRight
                                         ? hal::CaptureMode::kLeftOnly
                                         : hal::CaptureMode::kRightOnly;
    EXPECT_EQ(rig.core.capture_mode(), working);
    const std::optional<Emcy> e = rig.plc.WaitEmcy(uint16_t(EmcyCode::kSensor));
    ASSERT_TRUE(e);
    EXPECT_EQ(e->detail >> 24, kSensorOneCamera >> 24);
    EXPECT_EQ((e->detail >> 16) & 0xFF, missing == hal::StereoSide::kRight ? 1u : 0u);
    EXPECT_NE(e->state, FirmwareState::kFault);

    rig.plc.Trigger(1);
    std::optional<ResultSet> s = rig.plc.WaitSet();
    ASSERT_TRUE(s);
    EXPECT_EQ(s->status, ResultStatus::kMonocular);
    const SetScore c = ScoreSet(FallbackRig::World(), rig.data->table(), rig.table_ids, *s);
    std::printf("booted without the %s camera: %d of %zu objects, %d false\n",
                hal::StereoSideName(missing), c.correct,
                FallbackRig::World().scene(0).scene.objects.size(), c.false_alarms);
    EXPECT_GE(c.correct, 1);
    EXPECT_LE(c.false_alarms, c.correct);

    rig.plc.Send({0x04, 0, 0, 0, 0, 0, 0, 0});
    const std::optional<CommandAck> ack = rig.plc.WaitAck(0x04);
    ASSERT_TRUE(ack);
    EXPECT_EQ(ack->status, uint8_t(StatusCode::kFailedPrecondition));
    EXPECT_EQ(rig.core.capture_mode(), working);
    EXPECT_EQ(rig.core.state(), FirmwareState::kReady);
  }
}

// With neither a table pose nor a plane carried from stereo frames, one camera cannot tell depth:
// the sets go out empty with status 3 and an EMCY saying why, never guessed poses, and the node
// stays up (READY, its heartbeat on) until the camera is back.
TEST(FirmwareMonocular, WithoutAnyTablePlaneTheFallbackReportsNoPoses) {
  hal::SimCameraConfig cc;
  cc.right_absent = true;  // no stereo frame ever: nothing to estimate the plane from
  FallbackRig rig(cc);
  rig.Start(/*table_configured=*/false);
  ASSERT_EQ(rig.core.capture_mode(), hal::CaptureMode::kLeftOnly);
  for (uint16_t request = 1; request <= 2; ++request) {
    rig.plc.Trigger(request);
    const std::optional<ResultSet> s = rig.plc.WaitSet();
    ASSERT_TRUE(s);
    EXPECT_EQ(s->status, ResultStatus::kInternalError);
    EXPECT_EQ(s->object_count, 0);
    const std::optional<Emcy> e = rig.plc.WaitEmcy(uint16_t(EmcyCode::kSoftware));
    ASSERT_TRUE(e);
    EXPECT_EQ(e->detail >> 16, uint32_t(StatusCode::kFailedPrecondition));
  }
  EXPECT_EQ(rig.core.state(), FirmwareState::kReady);
  EXPECT_FALSE(rig.recognition->recognizer().mono_on_carried_plane());
}

// A busier cell: one scene of 8 objects in which the stereo search misses one (seed 31).
render::SimWorld& BusyWorld() {
  static render::SimWorld world;
  return FallbackRig::OneSceneWorld(&world, 8, 31);
}

// The stereo pipeline's one-image rescue on the fallback's recogniser, lent at boot: on the busy
// cell the sets hold at least as much of the truth as without the fallback (no recogniser to
// lend), nothing more that is false, and no heap allocation. On x86-64 the stereo search misses
// the object in each set, and the rescue runs on both frames and adds it (16 of 16); the aarch64
// build under qemu rounds differently, reports a false object over the missed one and leaves the
// gate shut. So that the rescue runs is asserted where the gate is open by construction (the
// tests below: a model left out of the mask).
TEST(FirmwareRescue, TheFallbacksRecogniserAddsWhatStereoMissed) {
  constexpr int kSets = 2;
  SetScore score[2];  // without the fallback, with it
  RescueCounters counters[2];
  for (const bool fallback : {false, true}) {
    FallbackRig rig(hal::SimCameraConfig{}, &BusyWorld());
    rig.Start(/*table_configured=*/true, /*confirm_frames=*/3, fallback);
    EXPECT_EQ(rig.recognition->recognizer().rescue_lent(), fallback);
    const uint64_t allocations_before = HeapAllocations();
    for (int i = 0; i < kSets; ++i) {
      rig.plc.Trigger(uint16_t(i + 1));
      const std::optional<ResultSet> s = rig.plc.WaitSet();
      ASSERT_TRUE(s);
      EXPECT_EQ(s->status, ResultStatus::kOk);
      const SetScore c = ScoreSet(BusyWorld(), rig.data->table(), rig.table_ids, *s);
      score[fallback].truth += c.truth;
      score[fallback].correct += c.correct;
      score[fallback].false_alarms += c.false_alarms;
    }
    counters[fallback] = rig.recognition->recognizer().rescue_counters();
    EXPECT_EQ(HeapAllocations() - allocations_before, 0u) << "heap allocations in triggers";
  }
  const RescueCounters& r = counters[1];
  std::printf(
      "busy cell, %d sets: stereo alone %d of %d correct, %d false; with the rescue %d "
      "correct, %d false (lent %llu frames, ran %llu, found %llu, added %llu)\n",
      kSets, score[0].correct, score[0].truth, score[0].false_alarms, score[1].correct,
      score[1].false_alarms, static_cast<unsigned long long>(r.frames_lent),
      static_cast<unsigned long long>(r.frames_ran), static_cast<unsigned long long>(r.found),
      static_cast<unsigned long long>(r.added));
  EXPECT_EQ(counters[0].frames_ran, 0u);
  EXPECT_EQ(r.lends, 1u);
  EXPECT_EQ(r.frames_lent, uint64_t(kSets));
  EXPECT_LE(r.added, r.found);
  EXPECT_LE(r.frames_ran, r.frames_lent);
  EXPECT_GE(score[1].correct, score[0].correct);
  EXPECT_LE(score[1].correct - score[0].correct, static_cast<int>(r.added));
  EXPECT_LE(score[1].false_alarms, score[0].false_alarms);
}

// The scene object whose model is masked in the rescue tests below, so that its corners stay
// free for the one-image rescue: one that shows at least the gate's six corners
// (RescueConfig::min_free_corners) above the automatic corner threshold.
constexpr int kRescuedObject = 2;

// Without the fallback (mono_fallback = false) there is no recogniser to lend: no rescue, on the
// same frames on which it runs with the fallback.
TEST(FirmwareRescue, WithoutTheFallbackTheRescueNeverRuns) {
  FallbackRig rig(hal::SimCameraConfig{});
  rig.hide_scene_object = kRescuedObject;
  rig.Start(/*table_configured=*/true, /*confirm_frames=*/3, /*fallback=*/false);
  for (int i = 0; i < 2; ++i) {
    rig.plc.Trigger(uint16_t(i + 1));
    const std::optional<ResultSet> s = rig.plc.WaitSet();
    ASSERT_TRUE(s);
    EXPECT_EQ(s->status, ResultStatus::kOk);
  }
  EXPECT_FALSE(rig.recognition->recognizer().rescue_lent());
  const RescueCounters r = rig.recognition->recognizer().rescue_counters();
  EXPECT_EQ(r.lends, 0u);
  EXPECT_EQ(r.frames_lent, 0u);
  EXPECT_EQ(r.frames_ran, 0u);
}

// A fallback on the right camera takes the recogniser from the rescue (set up for the right
// camera); back in stereo after clear-fault it is set up for the left one, lent again and runs.
TEST(FirmwareRescue, AfterARightCameraFallbackItIsLentForTheLeftCameraAgain) {
  hal::SimCameraConfig cc;
  cc.left_stop_after = 1;  // frame 0 paired, then the left camera is silent ...
  cc.fault_starts = 1;     // ... until the firmware restarts the camera
  FallbackRig rig(cc);
  rig.hide_scene_object = kRescuedObject;
  rig.Start();
  rig.plc.Trigger(1);
  std::optional<ResultSet> s = rig.plc.WaitSet();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->status, ResultStatus::kOk);
  const RescueCounters before = rig.recognition->recognizer().rescue_counters();
  EXPECT_EQ(before.frames_lent, 1u);

  rig.plc.Trigger(2);  // answered from the right camera
  s = rig.plc.WaitSet();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->status, ResultStatus::kMonocular);
  EXPECT_EQ(rig.core.capture_mode(), hal::CaptureMode::kRightOnly);
  EXPECT_FALSE(rig.recognition->recognizer().rescue_lent());

  rig.plc.Send({0x04, 0, 0, 0, 0, 0, 0, 0});
  const std::optional<CommandAck> ack = rig.plc.WaitAck(0x04);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, 0);
  EXPECT_EQ(rig.core.capture_mode(), hal::CaptureMode::kStereo);
  rig.plc.Trigger(3);
  s = rig.plc.WaitSet();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->status, ResultStatus::kOk);
  EXPECT_TRUE(rig.recognition->recognizer().rescue_lent());
  const RescueCounters after = rig.recognition->recognizer().rescue_counters();
  EXPECT_EQ(after.lends, before.lends + 1);
  EXPECT_EQ(after.frames_lent, before.frames_lent + 1);
  EXPECT_EQ(after.frames_ran, before.frames_ran + 1);
}

// select-models re-initialises the stereo pipeline, which takes the recogniser back: it is lent
// again and runs on the next frame (the newly masked model's object left to it).
TEST(FirmwareRescue, AModelMaskChangeLendsItAgain) {
  FallbackRig rig(hal::SimCameraConfig{});
  rig.Start();
  rig.plc.Trigger(1);
  std::optional<ResultSet> s = rig.plc.WaitSet();
  ASSERT_TRUE(s);
  const RescueCounters before = rig.recognition->recognizer().rescue_counters();
  const uint32_t mask = rig.core.model_mask() & ~rig.ModelBitOf(kRescuedObject);
  rig.plc.Send(
      {0x02, uint8_t(mask), uint8_t(mask >> 8), uint8_t(mask >> 16), uint8_t(mask >> 24), 0, 0, 0});
  const std::optional<CommandAck> ack = rig.plc.WaitAck(0x02);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, 0);
  rig.plc.Trigger(2);
  s = rig.plc.WaitSet();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->status, ResultStatus::kOk);
  EXPECT_EQ(rig.core.model_mask(), mask);
  EXPECT_TRUE(rig.recognition->recognizer().rescue_lent());
  const RescueCounters after = rig.recognition->recognizer().rescue_counters();
  EXPECT_EQ(after.lends, before.lends + 1);
  EXPECT_EQ(after.frames_lent, before.frames_lent + 1);
  EXPECT_EQ(after.frames_ran, before.frames_ran + 1);
}

}  // namespace
}  // namespace sh::testing
