// The firmware's table plane on a fixed cell (the simulator's world: one rig bolted over one
// table, every scene seen from it), through the board's recogniser (PipelineRecognition) with
// the simulated cameras: with no table pose and table_estimate = carry, the first frames
// estimate the plane, the plane is carried once three estimates agree, it agrees with the
// rendered table, the carried frames find what frames estimating their own plane find (per_frame)
// without touching the heap, and a new model mask keeps it; off uses no table.
// Own binary: it counts every operator new of the process.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "firmware/pipeline_recognition.hpp"
#include "firmware/truth_recognition.hpp"
#include "hal/sim/sim_camera.hpp"
#include "hal/sim/world/sim_world.hpp"
#include "set_score.hpp"
#include "tables/table_file.hpp"
#include "tests/support/counting_allocator.hpp"
#include "tests/support/sim_world_once.hpp"

namespace sh::testing {
namespace {

using fw::PipelineRecognition;
using protocol::ResultSet;
using protocol::TablePlane;
using sh::ObjectRecognizerConfig;

constexpr uint32_t kMask = 0x3F;  // the six reference polyhedra

render::SimWorld& World() {
  static render::SimWorld world;
  render::SimWorldConfig wc;
  wc.models_dir = STEREOHASH_FW_SOURCE_MODELS_DIR;
  wc.scenes = 8;
  wc.objects = 4;
  wc.seed = 31;
  EXPECT_TRUE(BuildOnce(world, wc));
  return world;
}

// The board's recogniser on the simulated cameras, one frame per Next().
class Cell {
 public:
  explicit Cell(const ObjectRecognizerConfig& config)
      : camera_(&World(), hal::SimCameraConfig{}), recognition_({&pipeline_}, config) {
    const Result<TableView> t = OpenDefaultTable();
    EXPECT_TRUE(t.ok());
    table_ = *t;
    fw::MapWorldModelsToIds(World(), ModelSet(&table_, nullptr), ids_);
    const Status s = recognition_.Init(World().calibration(), ModelSet(&table_, nullptr), kMask);
    EXPECT_TRUE(s.ok()) << s.message();
    EXPECT_TRUE(camera_.Start().ok());
  }
  ~Cell() { (void)camera_.Stop(); }

  // One frame into *set; *scene is the world's scene it showed.
  bool Next(ResultSet* set, int* scene) {
    hal::StereoFrame frame;
    if (!camera_.Capture(&frame, 5000).ok()) return false;
    *set = ResultSet{};
    const Status s = recognition_.Process(frame, 0.0f, set);  // no budget: poses, not time
    *scene = World().SceneOfFrame(frame.left_sequence);
    camera_.Release();
    return s.ok();
  }
  SetScore ScoreOf(const ResultSet& set, int scene) const {
    return ScoreSetOnScene(World(), table_, ids_, scene, set);
  }

  PipelineRecognition& recognition() { return recognition_; }
  ModelSet model_set() const { return ModelSet(&table_, nullptr); }
  static Pipeline& pipeline() { return pipeline_; }

 private:
  static Pipeline pipeline_;  // tens of MiB: static storage, as on the board
  hal::SimCamera camera_;
  PipelineRecognition recognition_;
  TableView table_;
  int ids_[render::kMaxWorldModels] = {};
};
Pipeline Cell::pipeline_;

constexpr int kFrames = 7;

TEST(FirmwareTableCarry, ThePlaneIsEstimatedConfirmedAndCarriedWithoutTheHeap) {
  static ResultSet set;
  // The same frames with the plane estimated in each (table_estimate = per_frame): the
  // reference for the carried frames' poses.
  SetScore reference[kFrames];
  {
    ObjectRecognizerConfig per_frame;
    per_frame.table_carry = false;
    Cell cell(per_frame);
    for (int i = 0; i < kFrames; ++i) {
      int scene = -1;
      ASSERT_TRUE(cell.Next(&set, &scene)) << "frame " << i;
      EXPECT_EQ(set.table, TablePlane::kEstimated) << "frame " << i;
      reference[i] = cell.ScoreOf(set, scene);
    }
    EXPECT_EQ(Cell::pipeline().table_carry().state(), TableCarryState::kSearching);
  }

  Cell cell{ObjectRecognizerConfig{}};  // the defaults: no table pose, table_estimate = carry
  SetScore carried, carried_reference;
  int estimated_frames = 0, carried_frames = 0;
  uint64_t carried_allocations = 0;
  std::printf("table planes:");
  for (int i = 0; i < kFrames; ++i) {
    const bool trusted_before = Cell::pipeline().table_carry().trusted();
    const uint64_t before = HeapAllocations();
    int scene = -1;
    ASSERT_TRUE(cell.Next(&set, &scene)) << "frame " << i;
    if (trusted_before) carried_allocations += HeapAllocations() - before;
    std::printf(" %s", protocol::TablePlaneName(set.table));
    // A frame carries exactly when enough agreeing estimates came before it; until then it
    // estimates.
    EXPECT_EQ(set.table, trusted_before ? TablePlane::kCarried : TablePlane::kEstimated)
        << "frame " << i;
    if (set.table != TablePlane::kCarried) {
      ++estimated_frames;
      continue;
    }
    ++carried_frames;
    const SetScore s = cell.ScoreOf(set, scene);
    carried.truth += s.truth;
    carried.correct += s.correct;
    carried.false_alarms += s.false_alarms;
    carried_reference.correct += reference[i].correct;
    carried_reference.false_alarms += reference[i].false_alarms;
  }
  std::printf("\ncarried frames: %d of %d correct, %d false (estimated in each: %d, %d false)\n",
              carried.correct, carried.truth, carried.false_alarms, carried_reference.correct,
              carried_reference.false_alarms);
  const TableCarry& carry = Cell::pipeline().table_carry();
  // Confirmed by three agreeing estimates (a first estimate off the table by a wrong object
  // starts the count again), then carried to the end without a drop.
  EXPECT_GE(estimated_frames, 3);
  EXPECT_GE(carried_frames, 3);
  EXPECT_TRUE(carry.trusted());
  EXPECT_EQ(carry.drops(), 0u);
  EXPECT_EQ(carry.misfits(), 0u);
  // The carried plane is the rendered table.
  EXPECT_TRUE(PlanesAgree(carry.left_T_table(), World().left_T_table(), 1.0f, 0.5f));
  // The carried frames find what the frames estimating their own plane find.
  EXPECT_GE(carried.correct, carried_reference.correct - 1);
  EXPECT_LE(carried.false_alarms, carried_reference.false_alarms + 1);
  EXPECT_EQ(carried_allocations, 0u) << "heap allocations in the carried frames";

  // A new model mask re-initialises the pipeline: the cameras did not move, the plane stays.
  ASSERT_TRUE(cell.recognition().SetModelMask(kMask).ok());
  EXPECT_TRUE(Cell::pipeline().table_carry().trusted());
  int scene = -1;
  ASSERT_TRUE(cell.Next(&set, &scene));
  EXPECT_EQ(set.table, TablePlane::kCarried);
}

TEST(FirmwareTableCarry, TheCarryKeysReachThePipeline) {
  ObjectRecognizerConfig keys;
  keys.table_confirm_frames = 5;  // table_confirm_frames = 5
  keys.table_check_frames = 0;    // table_check_frames = 0: only after a misfit
  Cell cell(keys);
  const TableCarryConfig& carry = Cell::pipeline().config().table_carry;
  EXPECT_TRUE(carry.enabled);
  EXPECT_EQ(carry.confirm_frames, 5u);
  EXPECT_EQ(carry.check_every_frames, 0u);
  // table_confirm_frames = 0 would never confirm: the pipeline refuses it at Init.
  ObjectRecognizerConfig never;
  never.table_confirm_frames = 0;
  PipelineRecognition refused({&Cell::pipeline()}, never);
  EXPECT_FALSE(refused.Init(World().calibration(), cell.model_set(), kMask).ok());
}

TEST(FirmwareTableCarry, OffUsesNoTable) {
  ObjectRecognizerConfig off;
  off.table_estimate = false;
  Cell cell(off);
  static ResultSet set;
  int scene = -1;
  ASSERT_TRUE(cell.Next(&set, &scene));
  EXPECT_EQ(set.table, TablePlane::kNone);
  EXPECT_EQ(Cell::pipeline().table_carry().state(), TableCarryState::kSearching);
}

}  // namespace
}  // namespace sh::testing
