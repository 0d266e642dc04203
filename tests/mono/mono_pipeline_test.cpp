// The monocular pipeline on one rendered scene: the same frame gives the same result, the time
// budget stops the search, and bad use is refused with a Status.
#include "recog/mono/mono_pipeline.hpp"

#include <gtest/gtest.h>

#include <memory>

#include "tests/mono/mono_render.hpp"

namespace sh {
namespace {

using testing::FakeClock;
using testing::MonoScene;
using testing::MonoScenes;
using testing::MonoSceneSet;

TEST(MonoPipeline, SameFrameSameResult) {
  const MonoSceneSet& f = MonoScenes();
  auto pipeline = std::make_unique<MonoPipeline>();
  auto workspace = MakeWorkspace<FeatureWorkspace>();
  auto a = std::make_unique<MonoResult>(), b = std::make_unique<MonoResult>();
  const RenderedPair& pair = MonoScene(0);
  const RigidTransform left_T_table = pair.generated.scene.left_T_table;
  ASSERT_TRUE(
      pipeline
          ->Init(pair.generated.calib, 0, f.table, &left_T_table, MonoPipelineConfig::Automatic())
          .ok());
  ASSERT_TRUE(pipeline->Process(pair.left_view(), 0, *workspace, a.get()).ok());
  ASSERT_TRUE(pipeline->Process(pair.left_view(), 0, *workspace, b.get()).ok());
  ASSERT_EQ(a->objects.size(), b->objects.size());
  for (size_t i = 0; i < a->objects.size(); ++i) {
    EXPECT_EQ(a->objects[i].model, b->objects[i].model);
    EXPECT_EQ(a->objects[i].cam_T_model.t_mm, b->objects[i].cam_T_model.t_mm);
  }
}

TEST(MonoPipeline, BudgetStopsTheSearch) {
  const MonoSceneSet& f = MonoScenes();
  auto pipeline = std::make_unique<MonoPipeline>();
  auto workspace = MakeWorkspace<FeatureWorkspace>();
  auto result = std::make_unique<MonoResult>();
  const RenderedPair& pair = MonoScene(1);
  const RigidTransform left_T_table = pair.generated.scene.left_T_table;
  ASSERT_TRUE(pipeline
                  ->Init(pair.generated.calib, 0, f.table, &left_T_table,
                         MonoPipelineConfig::Automatic(), FakeClock)
                  .ok());
  // FakeClock advances 1 us per call: a 1.5 us budget has passed when the search starts.
  ASSERT_TRUE(pipeline->Process(pair.left_view(), 0.0015f, *workspace, result.get()).ok());
  EXPECT_TRUE(result->stats.budget_exhausted);
  EXPECT_TRUE(result->objects.empty());
}

TEST(MonoPipeline, RefusesBadUse) {
  const MonoSceneSet& f = MonoScenes();
  auto pipeline = std::make_unique<MonoPipeline>();
  auto workspace = MakeWorkspace<FeatureWorkspace>();
  auto result = std::make_unique<MonoResult>();
  const RenderedPair& pair = MonoScene(0);
  EXPECT_EQ(pipeline->Process(pair.left_view(), 0, *workspace, result.get()).code(),
            StatusCode::kFailedPrecondition);
  EXPECT_EQ(pipeline->Init(pair.generated.calib, 2, f.table, nullptr, MonoPipelineConfig{}).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(
      pipeline->Init(pair.generated.calib, 0, AspectTableView{}, nullptr, MonoPipelineConfig{})
          .code(),
      StatusCode::kInvalidArgument);
  // A table above the camera (flipped): nothing can rest on it as seen from here.
  RigidTransform flipped = pair.generated.scene.left_T_table;
  flipped.t_mm = -flipped.t_mm;
  EXPECT_FALSE(
      pipeline->Init(pair.generated.calib, 0, f.table, &flipped, MonoPipelineConfig{}).ok());
  ASSERT_TRUE(pipeline->Init(pair.generated.calib, 0, f.table, nullptr, MonoPipelineConfig{}).ok());
  const ConstGrayView small{pair.left.data(), 100, 100, 100};
  EXPECT_EQ(pipeline->Process(small, 0, *workspace, result.get()).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(pipeline->Process(ConstGrayView{}, 0, *workspace, result.get()).code(),
            StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace sh
