// Proves that MonoPipeline::Process does not touch the heap: every operator new in this binary
// is counted, and the count must not change across Process() calls.
#include <gtest/gtest.h>

#include <memory>

#include "recog/mono/mono_pipeline.hpp"
#include "tables/aspect_file.hpp"
#include "tests/mono/mono_render.hpp"
#include "tests/support/counting_allocator.hpp"

namespace sh {
namespace {

using testing::FakeClock;  // timings exercised, the budget never reached

TEST(MonoAllocations, NoneWhileProcessing) {
  const Result<AspectTableView> table = OpenDefaultAspectTable();
  ASSERT_TRUE(table.ok()) << table.status().message();
  const RenderModels models = testing::MonoRenderModels(*table);
  auto pair = std::make_unique<RenderedPair>();
  render::ScenarioParams p;
  p.n_objects = 4;
  ASSERT_TRUE(RenderPair(21, p, models, pair.get()).ok());
  auto pipeline = std::make_unique<MonoPipeline>();
  auto workspace = MakeWorkspace<FeatureWorkspace>();
  auto result = std::make_unique<MonoResult>();
  const RigidTransform left_T_table = pair->generated.scene.left_T_table;
  size_t found = 0;
  uint64_t during = 0;
  for (const RigidTransform* t : {&left_T_table, static_cast<const RigidTransform*>(nullptr)}) {
    // Init (start-up) outside the count.
    ASSERT_TRUE(
        pipeline
            ->Init(pair->generated.calib, 0, *table, t, MonoPipelineConfig::Automatic(), FakeClock)
            .ok());
    const uint64_t before = testing::HeapAllocations();
    for (int repeat = 0; repeat < 2; ++repeat) {
      const Status s = pipeline->Process(pair->left_view(), 1000.0f, *workspace, result.get());
      ASSERT_TRUE(s.ok()) << s.message();
      found += result->objects.size();
    }
    ASSERT_FALSE(pipeline->Process(ConstGrayView{}, 0, *workspace, result.get()).ok());
    during += testing::HeapAllocations() - before;
  }
  EXPECT_EQ(during, 0u) << "heap allocations while processing frames";
  EXPECT_GT(found, 0u);
}

}  // namespace
}  // namespace sh
