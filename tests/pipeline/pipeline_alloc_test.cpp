// Proves that Pipeline::Process does not touch the heap: every operator new in this binary is
// counted, and the count must not change across Process() calls (scenes are rendered and the
// pipeline initialised before counting starts).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <memory>
#include <new>

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

TEST(PipelineAllocations, NoneWhileProcessing) {
  auto table = OpenDefaultTable();
  ASSERT_TRUE(table.ok());
  RenderModels models;
  ASSERT_TRUE(LoadRenderModels(STEREOHASH_MODELS_DIR, *table, &models).ok());
  std::vector<std::unique_ptr<RenderedPair>> pairs;
  for (render::Background bg : {render::Background::kDark, render::Background::kLight}) {
    render::ScenarioParams p;
    p.background = bg;
    p.n_objects = 4;
    pairs.push_back(std::make_unique<RenderedPair>());
    ASSERT_TRUE(RenderPair(31, p, models, pairs.back().get()).ok());
  }
  auto pipeline = std::make_unique<Pipeline>();
  static PipelineResult result;
  size_t found = 0, estimated_tables = 0;
  long during = 0;
  for (const auto& pair : pairs) {
    // Init (start-up, not per frame) with each scene's own calibration, outside the count.
    // Two threads: the second image's features and the search's votes ahead run on the pool.
    PipelineConfig config;
    config.threads = 2;
    ASSERT_TRUE(pipeline->Init(pair->generated.calib, *table, config, FakeClock).ok());
    const long before = testing::HeapAllocations();
    for (int repeat = 0; repeat < 2; ++repeat) {
      const Status s = pipeline->Process(pair->left_view(), pair->right_view(), 1000.0f, &result);
      ASSERT_TRUE(s.ok()) << s.message();
      found += result.objects.size();
      // No table given: the estimated one and the second search over it ran without the heap.
      if (result.table_source == TableSource::kEstimated) ++estimated_tables;
    }
    // Errors are reported without allocating too.
    ASSERT_FALSE(pipeline->Process(ConstGrayView{}, pair->right_view(), 0, &result).ok());
    during += testing::HeapAllocations() - before;
  }
  EXPECT_EQ(during, 0) << "heap allocations while processing frames";
  EXPECT_GT(found, 0u);  // the frames were actually recognised
  EXPECT_GT(estimated_tables, 0u);
  const long probe_before = testing::HeapAllocations();
  auto* probe = new int(1);
  const long probe_after = testing::HeapAllocations();
  delete probe;
  EXPECT_EQ(probe_after, probe_before + 1);
}

}  // namespace
}  // namespace sh
