// Proves that Pipeline::Process does not touch the heap: every operator new in this binary is
// counted, and the count must not change across Process() calls (scenes are rendered and the
// pipeline initialised before counting starts).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <memory>
#include <new>
#include <vector>

#include "recog/pipeline/pipeline.hpp"
#include "tables/table_file.hpp"
#include "tests/support/counting_allocator.hpp"
#include "tools/eval/rendered_eval.hpp"

namespace sh {
namespace {

int64_t FakeClock() {
  // Called from the pipeline's worker threads too: one atomic count.
  static std::atomic<int64_t> t{0};
  return t += 1000;  // 1 us per call: timings exercised, budget never reached
}

// A clock that jumps 1 ms per call: the budget runs out during the search on every frame,
// however fast or slow the machine.
int64_t JumpingClock() {
  static std::atomic<int64_t> t{0};
  return t += 1000000;
}

// One scene of four objects on a dark and on a light table, rendered and the pipeline made before
// anything is counted.
class PipelineAllocations : public ::testing::Test {
 protected:
  void SetUp() override {
    Result<TableView> opened = OpenDefaultTable();
    ASSERT_TRUE(opened.ok());
    table_ = *opened;
    RenderModels models;
    ASSERT_TRUE(LoadRenderModels(STEREOHASH_MODELS_DIR, table_, &models).ok());
    for (render::Background bg : {render::Background::kDark, render::Background::kLight}) {
      render::ScenarioParams p;
      p.background = bg;
      p.n_objects = 4;
      pairs_.push_back(std::make_unique<RenderedPair>());
      ASSERT_TRUE(RenderPair(31, p, models, pairs_.back().get()).ok());
    }
    pipeline_ = std::make_unique<Pipeline>();
  }

  // Init (start-up, not per frame) with the scene's own calibration, outside the count. Two
  // threads: the second image's features and the search's votes ahead run on the pool.
  Status InitFor(const RenderedPair& pair, Pipeline::ClockFn clock) {
    PipelineConfig config;
    config.threads = 2;
    return pipeline_->Init(pair.generated.calib, table_, config, clock);
  }

  TableView table_;
  std::vector<std::unique_ptr<RenderedPair>> pairs_;
  std::unique_ptr<Pipeline> pipeline_;
  PipelineResult result_;
};

TEST_F(PipelineAllocations, NoneWhileProcessing) {
  size_t found = 0, estimated_tables = 0;
  long during = 0;
  for (const auto& pair : pairs_) {
    ASSERT_TRUE(InitFor(*pair, FakeClock).ok());
    const long before = testing::HeapAllocations();
    for (int repeat = 0; repeat < 2; ++repeat) {
      const Status s = pipeline_->Process(pair->left_view(), pair->right_view(), 1000.0f, &result_);
      ASSERT_TRUE(s.ok()) << s.message();
      found += result_.objects.size();
      // No table given: the estimated one and the second search over it ran without the heap.
      if (result_.table_source == TableSource::kEstimated) ++estimated_tables;
    }
    // Errors are reported without allocating too.
    ASSERT_FALSE(pipeline_->Process(ConstGrayView{}, pair->right_view(), 0, &result_).ok());
    during += testing::HeapAllocations() - before;
  }
  EXPECT_EQ(during, 0) << "heap allocations while processing frames";
  EXPECT_GT(found, 0u);  // the frames were actually recognised
  EXPECT_GT(estimated_tables, 0u);
  const long probe_before = testing::HeapAllocations();
  // A direct call: the compiler may elide a new-expression paired with its delete.
  void* probe = ::operator new(sizeof(int));
  const long probe_after = testing::HeapAllocations();
  ::operator delete(probe);
  EXPECT_EQ(probe_after, probe_before + 1);
}

// The search cut short by the time budget (the firmware's status 1) leaves the heap alone too: on
// the jumping clock the budget runs out after the features and stereo, a few scene bases into the
// search.
TEST_F(PipelineAllocations, NoneWhenTheBudgetRunsOut) {
  int exhausted = 0;
  long during = 0;
  for (const auto& pair : pairs_) {
    ASSERT_TRUE(InitFor(*pair, JumpingClock).ok());
    const long before = testing::HeapAllocations();
    const Status s = pipeline_->Process(pair->left_view(), pair->right_view(), 40.0f, &result_);
    during += testing::HeapAllocations() - before;
    ASSERT_TRUE(s.ok()) << s.message();
    exhausted += result_.recognition.budget_exhausted ? 1 : 0;
    EXPECT_GT(result_.recognition.scene_bases_tried, 0u) << "cut short during the search";
  }
  EXPECT_EQ(during, 0) << "heap allocations while processing frames";
  EXPECT_EQ(exhausted, static_cast<int>(pairs_.size())) << "the budget ran out in every frame";
}

}  // namespace
}  // namespace sh
