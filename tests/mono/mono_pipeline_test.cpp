// The monocular pipeline on rendered scenes: objects found from one image with the table's
// pose, from either camera, and without a table; settings and errors.
#include "recog/mono/mono_pipeline.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>

#include "tables/aspect_file.hpp"
#include "tests/mono/mono_render.hpp"
#include "tools/eval/synthetic_scene.hpp"

namespace sh {
namespace {

int64_t FakeClock() {
  static int64_t t = 0;
  return t += 1000;  // 1 us per call
}

constexpr int kScenes = 4;

struct Fixture {
  AspectTableView table;
  RenderModels models;
  std::unique_ptr<RenderedPair> scenes[kScenes];
};

// Four scenes (dark and light table, two seeds each), each rendered once, when a test first
// asks for it (a ctest process runs one test: most need one scene).
Fixture& Models() {
  static Fixture* fixture = [] {
    auto* f = new Fixture;
    const Result<AspectTableView> t = OpenDefaultAspectTable();
    EXPECT_TRUE(t.ok()) << t.status().message();
    f->table = *t;
    f->models = testing::MonoRenderModels(f->table);
    return f;
  }();
  return *fixture;
}

const RenderedPair& Scene(int i) {
  Fixture& f = Models();
  if (f.scenes[i] == nullptr) {
    render::ScenarioParams p;
    p.background = i < 2 ? render::Background::kDark : render::Background::kLight;
    p.occlusion = render::Occlusion::kNone;
    p.n_objects = 4;
    p.camera_distance_mm = 450.0f;
    f.scenes[i] = std::make_unique<RenderedPair>();
    const Status s = RenderPair(11 + i % 2, p, f.models, f.scenes[i].get());
    EXPECT_TRUE(s.ok()) << s.message();
  }
  return *f.scenes[i];
}

struct Score {
  int objects = 0, correct = 0, reported = 0;
  std::vector<float> t_err, r_err;
};

void Add(const Fixture& f, const RenderedPair& pair, const MonoResult& r, float max_mm,
         Score* score) {
  std::vector<RecognizedPose> found;
  for (const RecognizedObject& o : r.objects) found.push_back({o.model, o.cam_T_model});
  const MatchCounts m = MatchToTruth(f.models.table, pair.truth, found, max_mm, 5.0f);
  score->objects += static_cast<int>(pair.truth.size());
  score->correct += m.correct;
  score->reported += static_cast<int>(r.objects.size());
  score->t_err.insert(score->t_err.end(), m.translation_errors_mm.begin(),
                      m.translation_errors_mm.end());
  score->r_err.insert(score->r_err.end(), m.rotation_errors_deg.begin(),
                      m.rotation_errors_deg.end());
}

float Median(std::vector<float> v) {
  if (v.empty()) return 0.0f;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

TEST(MonoPipeline, FindsRestingObjectsFromOneImageWithTheTable) {
  const Fixture& f = Models();
  auto pipeline = std::make_unique<MonoPipeline>();
  auto workspace = std::make_unique<FeatureWorkspace>();
  auto result = std::make_unique<MonoResult>();
  Score score;
  for (int i = 0; i < kScenes; ++i) {
    const RenderedPair* pair = &Scene(i);
    const RigidTransform left_T_table = pair->generated.scene.left_T_table;
    ASSERT_TRUE(pipeline
                    ->Init(pair->generated.calib, 0, f.table, &left_T_table,
                           MonoPipelineConfig::Automatic(), FakeClock)
                    .ok());
    ASSERT_TRUE(pipeline->Process(pair->left_view(), 0, *workspace, result.get()).ok());
    Add(f, *pair, *result, 5.0f, &score);
    EXPECT_GT(result->time.total_ms, 0.0f);
    EXPECT_GE(result->time.total_ms, result->time.features_ms);
    for (const RecognizedObject& o : result->objects) {
      EXPECT_GE(o.verify_score[0], pipeline->config().mono.verify.min_fraction);
      EXPECT_GE(o.verify_score[1], pipeline->config().mono.min_match_fraction);
    }
  }
  EXPECT_GE(score.correct * 4, score.objects * 3) << score.correct << " of " << score.objects;
  EXPECT_LE((score.reported - score.correct) * 5, score.reported);
  // The table fixes depth and tilt: millimetre poses from one image.
  EXPECT_LT(Median(score.t_err), 1.0f);
  EXPECT_LT(Median(score.r_err), 1.0f);
}

TEST(MonoPipeline, RightCameraReportsPosesInTheLeftFrame) {
  const Fixture& f = Models();
  auto pipeline = std::make_unique<MonoPipeline>();
  auto workspace = std::make_unique<FeatureWorkspace>();
  auto result = std::make_unique<MonoResult>();
  Score score;
  for (int i = 0; i < kScenes; ++i) {
    const RenderedPair* pair = &Scene(i);
    const RigidTransform left_T_table = pair->generated.scene.left_T_table;
    ASSERT_TRUE(pipeline
                    ->Init(pair->generated.calib, 1, f.table, &left_T_table,
                           MonoPipelineConfig::Automatic())
                    .ok());
    ASSERT_TRUE(pipeline->Process(pair->right_view(), 0, *workspace, result.get()).ok());
    Add(f, *pair, *result, 5.0f, &score);
  }
  EXPECT_GE(score.correct * 4, score.objects * 3) << score.correct << " of " << score.objects;
}

TEST(MonoPipeline, WithoutTableThePosesAreFreeButCoarser) {
  const Fixture& f = Models();
  auto pipeline = std::make_unique<MonoPipeline>();
  auto workspace = std::make_unique<FeatureWorkspace>();
  auto result = std::make_unique<MonoResult>();
  Score score;
  for (int i = 0; i < kScenes; ++i) {
    const RenderedPair* pair = &Scene(i);
    ASSERT_TRUE(
        pipeline->Init(pair->generated.calib, 0, f.table, nullptr, MonoPipelineConfig::Automatic())
            .ok());
    ASSERT_TRUE(pipeline->Process(pair->left_view(), 0, *workspace, result.get()).ok());
    Add(f, *pair, *result, 15.0f, &score);
  }
  // Depth from one image without the table is the weak direction: within 15 mm for some.
  EXPECT_GT(score.correct, 0);
}

TEST(MonoPipeline, SameFrameSameResult) {
  const Fixture& f = Models();
  auto pipeline = std::make_unique<MonoPipeline>();
  auto workspace = std::make_unique<FeatureWorkspace>();
  auto a = std::make_unique<MonoResult>(), b = std::make_unique<MonoResult>();
  const RenderedPair& pair = Scene(0);
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
  const Fixture& f = Models();
  auto pipeline = std::make_unique<MonoPipeline>();
  auto workspace = std::make_unique<FeatureWorkspace>();
  auto result = std::make_unique<MonoResult>();
  const RenderedPair& pair = Scene(1);
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
  const Fixture& f = Models();
  auto pipeline = std::make_unique<MonoPipeline>();
  auto workspace = std::make_unique<FeatureWorkspace>();
  auto result = std::make_unique<MonoResult>();
  const RenderedPair& pair = Scene(0);
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
