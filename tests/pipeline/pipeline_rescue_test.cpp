// The one-image rescue (PipelineConfig::rescue) on rendered stereo pairs: with stereo's 3-D
// features taken away (every line pair treated as degenerate, points whose rays do not meet
// within a hundredth of a millimetre), the stereo search finds nothing and the rescue finds the
// objects from the left image and then the right, each confirmed in both; a right image without the
// objects refuses every one-image hypothesis; the rescue allocates nothing (this binary counts
// operator new).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <memory>
#include <vector>

#include "recog/mono/mono_pipeline.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "recog/verify/view_camera.hpp"
#include "tables/aspect_file.hpp"
#include "tables/table_file.hpp"
#include "tests/support/counting_allocator.hpp"
#include "tests/support/same_objects.hpp"
#include "tools/eval/rendered_eval.hpp"

namespace sh {
namespace {

// Atomic: with two threads the verifier reads the clock on the pool's threads too.
int64_t FakeClock() {
  static std::atomic<int64_t> t{0};
  return t += 1000;  // 1 us per call: the budget is never reached
}

constexpr int kScenes = 4;

class PipelineRescue : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const Result<TableView> t = OpenDefaultTable();
    ASSERT_TRUE(t.ok()) << t.status().message();
    table_ = new TableView(*t);
    const Result<AspectTableView> a = OpenDefaultAspectTable();
    ASSERT_TRUE(a.ok()) << a.status().message();
    aspects_ = new AspectTableView(*a);
    models_ = new RenderModels();
    ASSERT_TRUE(LoadRenderModels(STEREOHASH_MODELS_DIR, *table_, models_).ok());
    pairs_ = new std::vector<std::unique_ptr<RenderedPair>>();
    for (int i = 0; i < kScenes; ++i) {
      render::ScenarioParams p;
      p.background = render::Background::kDark;
      p.occlusion = render::Occlusion::kNone;
      p.n_objects = 3;
      p.camera_distance_mm = 400.0f;
      auto pair = std::make_unique<RenderedPair>();
      ASSERT_TRUE(RenderPair(uint64_t(7100 + i), p, *models_, pair.get()).ok());
      pairs_->push_back(std::move(pair));
    }
    pipeline_ = new Pipeline();
    mono_ = new MonoRecognizer();
    result_ = new PipelineResult();
  }
  static void TearDownTestSuite() {
    delete result_;
    delete mono_;
    delete pipeline_;
    delete pairs_;
    delete models_;
    delete aspects_;
    delete table_;
  }

  // The pipeline for one scene's calibration and table, its 3-D features taken away when asked,
  // and the rescue's recogniser lent (rescue on) or not.
  static void SetUp(const RenderedPair& pair, bool lose_stereo, bool rescue, bool table = true,
                    bool right_image = true, bool gate_open = false, int threads = 1,
                    bool edge_fit = true) {
    PipelineConfig config = PipelineConfig::Automatic();
    config.rescue.right_image = right_image;
    config.rescue.edge_fit = edge_fit;
    if (gate_open) config.rescue.min_free_corners = 0;
    config.table.known = table;
    config.table.left_T_table = pair.generated.scene.left_T_table;
    config.threads = threads;
    if (lose_stereo) {
      config.stereo.min_plane_angle_deg = 89.9f;
      config.stereo.max_ray_gap_mm = 0.01f;
    }
    ASSERT_TRUE(pipeline_->Init(pair.generated.calib, *table_, config, FakeClock).ok());
    ASSERT_TRUE(mono_
                    ->Init(LeftView(pair.generated.calib), *aspects_,
                           table ? &pair.generated.scene.left_T_table : nullptr,
                           MonoPipelineConfig::Automatic().mono)
                    .ok());
    if (rescue) {
      ASSERT_TRUE(pipeline_->LendRescue(mono_).ok());
    }
  }

  static TableView* table_;
  static AspectTableView* aspects_;
  static RenderModels* models_;
  static std::vector<std::unique_ptr<RenderedPair>>* pairs_;
  static Pipeline* pipeline_;
  static MonoRecognizer* mono_;
  static PipelineResult* result_;
};

TableView* PipelineRescue::table_ = nullptr;
AspectTableView* PipelineRescue::aspects_ = nullptr;
RenderModels* PipelineRescue::models_ = nullptr;
std::vector<std::unique_ptr<RenderedPair>>* PipelineRescue::pairs_ = nullptr;
Pipeline* PipelineRescue::pipeline_ = nullptr;
MonoRecognizer* PipelineRescue::mono_ = nullptr;
PipelineResult* PipelineRescue::result_ = nullptr;

TEST_F(PipelineRescue, FindsWhatStereoLostAndConfirmsItInBothImages) {
  int truth = 0, stereo_alone = 0, rescued = 0, rescued_correct = 0, rescued_false = 0;
  for (const auto& pair : *pairs_) {
    truth += static_cast<int>(pair->truth.size());
    SetUp(*pair, /*lose_stereo=*/true, /*rescue=*/false);
    ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, result_).ok());
    stereo_alone += MatchToTruth(models_->table, pair->truth, PosesOf(*result_)).correct;
    EXPECT_FALSE(result_->rescue.ran);  // not lent: no rescue

    SetUp(*pair, /*lose_stereo=*/true, /*rescue=*/true);
    ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, result_).ok());
    EXPECT_TRUE(result_->rescue.ran);
    EXPECT_EQ(result_->rescue.added, result_->objects.size());  // stereo found nothing
    const MatchCounts m = MatchToTruth(models_->table, pair->truth, PosesOf(*result_));
    rescued += static_cast<int>(result_->rescue.added);
    rescued_correct += m.correct;
    rescued_false += m.false_alarms;
    // Confirmed in both images by the stereo verifier, then fitted to both edge maps.
    for (const RecognizedObject& o : result_->objects) {
      EXPECT_GT(o.verify_score[0], 0.5f);
      EXPECT_GT(o.verify_score[1], 0.5f);
    }
  }
  std::printf("%d objects, stereo without 3-D features finds %d, the rescue %d (%d correct)\n",
              truth, stereo_alone, rescued, rescued_correct);
  EXPECT_EQ(stereo_alone, 0);
  EXPECT_GE(rescued_correct * 2, truth);  // at least half from one image
  EXPECT_EQ(rescued_false, 0);
}

TEST_F(PipelineRescue, SearchesTheRightImageAfterTheLeftAndSetsTheRecogniserBack) {
  int left_only = 0, both = 0, false_both = 0;
  for (const auto& pair : *pairs_) {
    SetUp(*pair, /*lose_stereo=*/true, /*rescue=*/true, /*table=*/true, /*right_image=*/false);
    ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, result_).ok());
    EXPECT_FALSE(result_->rescue.ran_right);
    left_only += MatchToTruth(models_->table, pair->truth, PosesOf(*result_)).correct;

    // With the gate open, the right image is searched in every frame, after the left.
    SetUp(*pair, /*lose_stereo=*/true, /*rescue=*/true, /*table=*/true, /*right_image=*/true,
          /*gate_open=*/true);
    ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, result_).ok());
    EXPECT_TRUE(result_->rescue.ran_right);
    const MatchCounts m = MatchToTruth(models_->table, pair->truth, PosesOf(*result_));
    both += m.correct;
    false_both += m.false_alarms;
    // The recogniser lent for the left camera is set back to it.
    const ViewCamera left = LeftView(pair->generated.calib);
    EXPECT_LT((mono_->camera().cam_T_left.t_mm - left.cam_T_left.t_mm).norm(), 1e-6f);
    EXPECT_EQ(mono_->camera().intrinsics.cx, left.intrinsics.cx);
  }
  std::printf("rescued from the left image %d, from both %d\n", left_only, both);
  EXPECT_GE(both, left_only);
  EXPECT_EQ(false_both, 0);
}

// A pose from one image rests on the recogniser's table: where that plane is off by a little (a
// table calibrated a while ago), so is every pose it gives, which both images' edges show. Fitted
// to them before the stereo verifier sees it, the candidate lies where the object is. (The
// pipeline's final edge fit is off here, so that the poses reported are the ones verified.)
TEST_F(PipelineRescue, FitsOneImagePosesToBothImagesBeforeVerifying) {
  int fitted[2] = {0, 0}, correct[2] = {0, 0}, false_alarms[2] = {0, 0};
  double error_mm[2] = {0.0, 0.0};
  for (const auto& pair : *pairs_) {
    for (int fit = 0; fit < 2; ++fit) {
      SetUp(*pair, /*lose_stereo=*/true, /*rescue=*/false, /*table=*/true, /*right_image=*/false,
            /*gate_open=*/false, /*threads=*/1, /*edge_fit=*/fit == 1);
      PipelineConfig config = pipeline_->config();
      config.edge_refine = false;
      ASSERT_TRUE(pipeline_->Init(pair->generated.calib, *table_, config, FakeClock).ok());
      // The one-image recogniser's table 1.5 mm above the true one.
      RigidTransform raised = pair->generated.scene.left_T_table;
      raised.t_mm += 1.5f * raised.R.col(2);
      ASSERT_TRUE(mono_
                      ->Init(LeftView(pair->generated.calib), *aspects_, &raised,
                             MonoPipelineConfig::Automatic().mono)
                      .ok());
      ASSERT_TRUE(pipeline_->LendRescue(mono_).ok());
      ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, result_).ok());
      fitted[fit] += static_cast<int>(result_->rescue.edge_fitted);
      const MatchCounts m = MatchToTruth(models_->table, pair->truth, PosesOf(*result_));
      correct[fit] += m.correct;
      false_alarms[fit] += m.false_alarms;
      for (const float e : m.translation_errors_mm) error_mm[fit] += e;
    }
  }
  std::printf(
      "edge fit off / on: %d / %d correct, %d / %d false, mean error %.3f / %.3f mm; "
      "%d poses moved\n",
      correct[0], correct[1], false_alarms[0], false_alarms[1],
      error_mm[0] / std::max(1, correct[0]), error_mm[1] / std::max(1, correct[1]), fitted[1]);
  EXPECT_EQ(fitted[0], 0);
  EXPECT_GT(fitted[1], 0);
  EXPECT_GE(correct[1], correct[0]);
  EXPECT_EQ(false_alarms[1], 0);
  ASSERT_GT(correct[0], 0);
  EXPECT_LT(error_mm[1] / correct[1], 0.5 * error_mm[0] / correct[0]);
}

TEST_F(PipelineRescue, ReportsNoObjectTwice) {
  // Stereo intact: what the rescue adds lies outside the objects stereo found.
  int correct_without = 0, false_without = 0, correct_with = 0, false_with = 0;
  for (const auto& pair : *pairs_) {
    SetUp(*pair, /*lose_stereo=*/false, /*rescue=*/false);
    ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, result_).ok());
    const MatchCounts before = MatchToTruth(models_->table, pair->truth, PosesOf(*result_));
    correct_without += before.correct;
    false_without += before.false_alarms;
    SetUp(*pair, /*lose_stereo=*/false, /*rescue=*/true);
    ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, result_).ok());
    const MatchCounts m = MatchToTruth(models_->table, pair->truth, PosesOf(*result_));
    correct_with += m.correct;
    false_with += m.false_alarms;
    for (size_t i = 0; i < result_->objects.size(); ++i) {
      for (size_t j = 0; j < i; ++j) {
        const float d =
            (result_->objects[i].cam_T_model.t_mm - result_->objects[j].cam_T_model.t_mm).norm();
        EXPECT_GT(d, 15.0f) << "objects " << j << " and " << i;
      }
    }
  }
  EXPECT_GE(correct_with, correct_without);
  EXPECT_LE(false_with, false_without);  // the rescue adds none
}

TEST_F(PipelineRescue, WithoutATableItSearchesOnTheEstimatedOneAndGivesTheRecogniserBack) {
  int estimated = 0, false_with = 0, false_without = 0;
  for (const auto& pair : *pairs_) {
    SetUp(*pair, /*lose_stereo=*/false, /*rescue=*/false, /*table=*/false);
    ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, result_).ok());
    false_without += MatchToTruth(models_->table, pair->truth, PosesOf(*result_)).false_alarms;
    SetUp(*pair, /*lose_stereo=*/false, /*rescue=*/true, /*table=*/false);
    ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, result_).ok());
    false_with += MatchToTruth(models_->table, pair->truth, PosesOf(*result_)).false_alarms;
    estimated += result_->table_source == TableSource::kEstimated;
    EXPECT_FALSE(mono_->has_table());  // the estimated plane was lent for the search only
  }
  EXPECT_GT(estimated, 0);
  EXPECT_LE(false_with, false_without);
}

TEST_F(PipelineRescue, RefusesWhatTheRightImageDoesNotShow) {
  // The right image: the table alone (its background grey, no object edges).
  const RenderedPair& pair = *(*pairs_)[0];
  std::vector<uint8_t> empty(pair.right.size(), pair.right[0]);
  const ConstGrayView right{empty.data(), pair.generated.calib.right.width,
                            pair.generated.calib.right.height, pair.generated.calib.right.width};
  SetUp(pair, /*lose_stereo=*/false, /*rescue=*/true);
  ASSERT_TRUE(pipeline_->Process(pair.left_view(), right, 0, result_).ok());
  EXPECT_TRUE(result_->rescue.ran);
  EXPECT_GT(result_->rescue.found, 0u);  // the left image alone shows the objects
  EXPECT_EQ(result_->rescue.refused_verify, result_->rescue.found);
  EXPECT_EQ(result_->rescue.added, 0u);
  EXPECT_TRUE(result_->objects.empty());
}

TEST_F(PipelineRescue, SwitchedOffItDoesNotRun) {
  const RenderedPair& pair = *(*pairs_)[0];
  SetUp(pair, /*lose_stereo=*/true, /*rescue=*/true);
  PipelineConfig config = pipeline_->config();
  config.rescue.enabled = false;
  ASSERT_TRUE(pipeline_->Init(pair.generated.calib, *table_, config, FakeClock).ok());
  ASSERT_TRUE(pipeline_->LendRescue(mono_).ok());
  ASSERT_TRUE(pipeline_->Process(pair.left_view(), pair.right_view(), 0, result_).ok());
  EXPECT_FALSE(result_->rescue.ran);
  EXPECT_TRUE(result_->objects.empty());
}

TEST_F(PipelineRescue, RefusesARecogniserOfOtherModels) {
  const RenderedPair& pair = *(*pairs_)[0];
  SetUp(pair, false, false);
  static MonoRecognizer unset;  // no aspect table
  EXPECT_FALSE(pipeline_->LendRescue(&unset).ok());
  EXPECT_TRUE(pipeline_->LendRescue(nullptr).ok());
}

TEST_F(PipelineRescue, LentItSharesThePoolAndInitTakesItBack) {
  const RenderedPair& pair = *(*pairs_)[0];
  SetUp(pair, false, false);
  PipelineConfig config = pipeline_->config();
  config.threads = 2;
  ASSERT_TRUE(pipeline_->Init(pair.generated.calib, *table_, config, FakeClock).ok());
  ASSERT_TRUE(pipeline_->LendRescue(mono_).ok());
  EXPECT_EQ(mono_->evaluation_threads(), 2);
  // A pipeline set up again no longer holds the recogniser: it searches on its caller alone.
  ASSERT_TRUE(pipeline_->Init(pair.generated.calib, *table_, config, FakeClock).ok());
  EXPECT_EQ(mono_->evaluation_threads(), 1);
  ASSERT_TRUE(pipeline_->LendRescue(mono_).ok());
  EXPECT_EQ(mono_->evaluation_threads(), 2);
  EXPECT_TRUE(pipeline_->LendRescue(nullptr).ok());
  EXPECT_EQ(mono_->evaluation_threads(), 1);
}

// The stereo search's and the rescue's counts, in one array to compare.
std::vector<uint32_t> SearchCounts(const PipelineResult& r) {
  const RecognitionStats& s = r.recognition;
  const MonoStats& m = r.rescue.search;
  const MonoStats& mr = r.rescue.search_right;
  return {s.scene_bases_tried, s.scene_bases_available,
          s.hypotheses,        s.verifications,
          s.accepted,          r.rescue.ran,
          r.rescue.ran_right,  r.rescue.found,
          r.rescue.added,      m.scene_bases_tried,
          m.hypotheses,        m.verifications,
          m.accepted,          mr.scene_bases_tried,
          mr.hypotheses,       mr.accepted};
}

// With two threads the rescue votes in the stereo recogniser's second vote scratch: the same
// objects and counts as on one thread, in two frames in a row (the stereo search of the second
// runs in the scratch the first frame's rescue wrote; the second frame starts from what the
// first carried over, on either thread count).
TEST_F(PipelineRescue, VotingInTheStereoScratchChangesNothing) {
  int rescued = 0;
  for (const auto& pair : *pairs_) {
    for (const bool lose_stereo : {false, true}) {
      Vector<RecognizedObject, kMaxObjects> serial[2];
      std::vector<uint32_t> serial_counts[2];
      SetUp(*pair, lose_stereo, /*rescue=*/true, true, true, /*gate_open=*/true, /*threads=*/1);
      for (int frame = 0; frame < 2; ++frame) {
        ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, result_).ok());
        ASSERT_TRUE(result_->rescue.ran);
        for (const RecognizedObject& o : result_->objects) {
          ASSERT_TRUE(serial[frame].push_back(o));
        }
        serial_counts[frame] = SearchCounts(*result_);
        rescued += static_cast<int>(result_->rescue.found);
      }
      SetUp(*pair, lose_stereo, /*rescue=*/true, true, true, /*gate_open=*/true, /*threads=*/2);
      ASSERT_EQ(mono_->evaluation_threads(), 2);
      for (int frame = 0; frame < 2; ++frame) {
        ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, result_).ok());
        testing::ExpectSameObjects(serial[frame], result_->objects, static_cast<uint64_t>(frame));
        EXPECT_EQ(SearchCounts(*result_), serial_counts[frame]) << "frame " << frame;
      }
      EXPECT_FALSE(mono_->votes_in_parallel());  // the scratch is given back after the rescue
    }
  }
  EXPECT_GT(rescued, 0);
}

TEST_F(PipelineRescue, NoAllocationWhileRescuing) {
  size_t rescued = 0;
  for (const auto& pair : *pairs_) {
    SetUp(*pair, /*lose_stereo=*/true, /*rescue=*/true);
    // The first frame after Init may touch lazily set-up state: it is not counted.
    ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, result_).ok());
    const uint64_t before = testing::HeapAllocations();
    ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, result_).ok());
    EXPECT_EQ(testing::HeapAllocations() - before, 0u) << "heap allocations while rescuing";
    rescued += result_->rescue.added;
  }
  EXPECT_GT(rescued, 0u);
}

}  // namespace
}  // namespace sh
