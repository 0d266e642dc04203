// The texture path end to end on rendered printed cartons: found at their poses, nothing else
// reported, the same with one or two threads, and no heap in the per-frame path.
#include "recog/texture/texture_recognizer.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <vector>

#include "hal/sim/textured_model_files.hpp"
#include "hal/sim/world/printed_surface.hpp"
#include "hal/sim/world/renderer.hpp"
#include "hal/sim/world/scene_generator.hpp"
#include "recog/base/crc32.hpp"
#include "recog/pipeline/worker_pool.hpp"
#include "tests/support/aligned_blob.hpp"
#include "tests/support/counting_allocator.hpp"
#include "tools/tablegen/feature_db_builder.hpp"

namespace sh::texture {
namespace {

struct Fixture {
  std::vector<TexturedModel> printed;
  std::vector<Model> models;
  std::vector<render::PrintedSurface> prints;
  std::unique_ptr<testing::AlignedBlob> blob;
  FeatureDbView db;
};

// Tea and pills, learnt with the default views.
const Fixture& Cartons() {
  static const std::unique_ptr<Fixture> f = [] {
    auto fx = std::make_unique<Fixture>();
    for (const char* name : {"tea", "pills"}) {
      Result<TexturedModel> m =
          LoadTexturedModelFile(std::string("models/textured/") + name + ".obj");
      EXPECT_TRUE(m.ok()) << m.status().message();
      fx->printed.push_back(*m);
      fx->models.push_back(m->model);
    }
    for (const TexturedModel& t : fx->printed) fx->prints.push_back(render::PrintOf(t));
    Result<std::vector<uint8_t>> blob = BuildFeatureDb(fx->printed, FeatureDbBuildOptions{});
    EXPECT_TRUE(blob.ok()) << blob.status().message();
    fx->blob = std::make_unique<testing::AlignedBlob>(*blob);
    Result<FeatureDbView> view = FeatureDbView::Open(fx->blob->data, fx->blob->size);
    EXPECT_TRUE(view.ok()) << view.status().message();
    fx->db = *view;
    return fx;
  }();
  return *f;
}

struct Rendered {
  render::GeneratedScene scene;
  std::vector<uint8_t> left, right;
  ConstGrayView left_view() const {
    const CameraIntrinsics& c = scene.calib.left;
    return {left.data(), c.width, c.height, c.width};
  }
  ConstGrayView right_view() const {
    const CameraIntrinsics& c = scene.calib.right;
    return {right.data(), c.width, c.height, c.width};
  }
};

Rendered Render(const Fixture& f, uint64_t seed, render::Background background) {
  render::ScenarioParams p;
  p.n_objects = 2;
  p.background = background;
  p.occlusion = render::Occlusion::kNone;
  p.camera_distance_mm = 420.0f;
  p.spread_mm = 250.0f;
  Result<render::GeneratedScene> g =
      render::GenerateScene(seed, p, f.models.data(), static_cast<int>(f.models.size()));
  EXPECT_TRUE(g.ok()) << g.status().message();
  Rendered r;
  r.scene = *g;
  for (render::SceneObject& o : r.scene.scene.objects) {
    o.albedo = 0.95f;
    o.print = &f.prints[o.model_index];
  }
  const CameraIntrinsics& c = r.scene.calib.left;
  r.left.resize(size_t{1} * c.width * c.height);
  r.right.resize(r.left.size());
  EXPECT_TRUE(render::RenderStereo(r.scene.scene, f.models.data(),
                                   static_cast<int>(f.models.size()), r.scene.calib,
                                   GrayView{r.left.data(), c.width, c.height, c.width},
                                   GrayView{r.right.data(), c.width, c.height, c.width})
                  .ok());
  return r;
}

void ExpectFoundAtTheirPoses(const Fixture& f, const Rendered& r, const TextureResult& result) {
  ASSERT_EQ(result.objects.size(), r.scene.scene.objects.size());
  for (size_t k = 0; k < r.scene.scene.objects.size(); ++k) {
    const int model = r.scene.scene.objects[k].model_index;
    const RigidTransform& truth = r.scene.left_T_model[k];
    bool found = false;
    for (const TextureObject& o : result.objects) {
      if (std::strcmp(f.db.model(o.model).name, f.models[static_cast<size_t>(model)].name) != 0) {
        continue;
      }
      const float t_err = (o.cam_T_model.t_mm - truth.t_mm).norm();
      const float r_err = RotationAngleDeg(o.cam_T_model.R.transpose() * truth.R);
      found |= t_err < 1.0f && r_err < 1.0f;
      EXPECT_GT(o.print.zncc[0], 0.7f);
      EXPECT_GT(o.print.zncc[1], 0.7f);
    }
    EXPECT_TRUE(found) << f.models[static_cast<size_t>(model)].name;
  }
}

TEST(TextureRecognizer, FindsRenderedCartonsAtTheirPoses) {
  const Fixture& f = Cartons();
  auto rec = std::make_unique<TextureRecognizer>();
  auto result = std::make_unique<TextureResult>();
  for (render::Background bg : {render::Background::kDark, render::Background::kLight}) {
    const Rendered r = Render(f, 31, bg);
    ASSERT_TRUE(rec->Init(r.scene.calib, f.db, TextureRecognizerConfig{}).ok());
    ASSERT_TRUE(rec->Process(r.left_view(), r.right_view(), result.get()).ok());
    ExpectFoundAtTheirPoses(f, r, *result);
    EXPECT_GE(result->stats.faces_3d, 2u);
  }
}

TEST(TextureRecognizer, TwoThreadsGiveTheSamePosesAndNoHeapPerFrame) {
  const Fixture& f = Cartons();
  const Rendered r = Render(f, 47, render::Background::kDark);
  auto one = std::make_unique<TextureRecognizer>();
  auto two = std::make_unique<TextureRecognizer>();
  auto a = std::make_unique<TextureResult>();
  auto b = std::make_unique<TextureResult>();
  WorkerPool pool;
  ASSERT_TRUE(pool.Start(2).ok());
  const ParallelFor parallel = ParallelOn(&pool);
  ASSERT_TRUE(one->Init(r.scene.calib, f.db, TextureRecognizerConfig{}).ok());
  ASSERT_TRUE(two->Init(r.scene.calib, f.db, TextureRecognizerConfig{}, nullptr, parallel).ok());
  ASSERT_TRUE(one->Process(r.left_view(), r.right_view(), a.get()).ok());
  ASSERT_TRUE(two->Process(r.left_view(), r.right_view(), b.get()).ok());
  // Later frames: every table built on first use exists; nothing may allocate now.
  const uint64_t before = testing::HeapAllocations();
  ASSERT_TRUE(two->Process(r.left_view(), r.right_view(), b.get()).ok());
  EXPECT_EQ(testing::HeapAllocations(), before);
  ExpectFoundAtTheirPoses(f, r, *a);
  ASSERT_EQ(a->objects.size(), b->objects.size());
  for (size_t i = 0; i < a->objects.size(); ++i) {
    EXPECT_EQ(a->objects[i].model, b->objects[i].model);
    EXPECT_EQ(a->objects[i].cam_T_model.t_mm, b->objects[i].cam_T_model.t_mm);
    EXPECT_EQ(a->objects[i].cam_T_model.R, b->objects[i].cam_T_model.R);
  }
  EXPECT_EQ(a->stats.matches, b->stats.matches);
}

TEST(TextureRecognizer, AnEmptyTableReportsNothing) {
  const Fixture& f = Cartons();
  render::ScenarioParams p;
  p.n_objects = 1;
  Result<render::GeneratedScene> g =
      render::GenerateScene(5, p, f.models.data(), static_cast<int>(f.models.size()));
  ASSERT_TRUE(g.ok());
  g->scene.objects.clear();  // the table alone
  const CameraIntrinsics& c = g->calib.left;
  std::vector<uint8_t> left(size_t{1} * c.width * c.height), right(left.size());
  ASSERT_TRUE(render::RenderStereo(g->scene, f.models.data(), static_cast<int>(f.models.size()),
                                   g->calib, GrayView{left.data(), c.width, c.height, c.width},
                                   GrayView{right.data(), c.width, c.height, c.width})
                  .ok());
  auto rec = std::make_unique<TextureRecognizer>();
  auto result = std::make_unique<TextureResult>();
  ASSERT_TRUE(rec->Init(g->calib, f.db, TextureRecognizerConfig{}).ok());
  ASSERT_TRUE(rec->Process({left.data(), c.width, c.height, c.width},
                           {right.data(), c.width, c.height, c.width}, result.get())
                  .ok());
  EXPECT_TRUE(result->objects.empty());
}

TEST(TextureRecognizer, RefusesImagesThatDoNotMatchTheCalibration) {
  const Fixture& f = Cartons();
  const Rendered r = Render(f, 31, render::Background::kDark);
  auto rec = std::make_unique<TextureRecognizer>();
  auto result = std::make_unique<TextureResult>();
  EXPECT_EQ(rec->Process(r.left_view(), r.right_view(), result.get()).code(),
            StatusCode::kFailedPrecondition);  // not initialised
  ASSERT_TRUE(rec->Init(r.scene.calib, f.db, TextureRecognizerConfig{}).ok());
  ConstGrayView small = r.left_view();
  small.width -= 10;
  const Status s = rec->Process(small, r.right_view(), result.get());
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::strstr(s.message(), "calibration says"), nullptr) << s.message();
  EXPECT_EQ(rec->Init(r.scene.calib, FeatureDbView{}, TextureRecognizerConfig{}).code(),
            StatusCode::kFailedPrecondition);
}

// The database reader checks the stored extraction settings only against the format (levels in
// range, numbers finite); whether an extractor takes them is the recogniser's check, which must
// refuse such a database by name rather than fail on every frame.
TEST(TextureRecognizer, RefusesADatabaseLearntWithSettingsNoExtractorTakes) {
  const Fixture& f = Cartons();
  testing::AlignedBlob blob(std::vector<uint8_t>(f.blob->data, f.blob->data + f.blob->size));
  auto& header = *reinterpret_cast<FeatureDbHeader*>(blob.data);
  header.extraction.harris_k = 0.3f;  // finite, but outside the Harris detector's (0, 0.25)
  header.blob_crc32 = 0;
  header.blob_crc32 = BlobCrc32(blob.data, blob.size, offsetof(FeatureDbHeader, blob_crc32));
  Result<FeatureDbView> db = FeatureDbView::Open(blob.data, blob.size);
  ASSERT_TRUE(db.ok()) << db.status().message();

  // Init needs a calibration only: the scene is generated, not rendered.
  Result<render::GeneratedScene> g = render::GenerateScene(
      5, render::ScenarioParams{}, f.models.data(), static_cast<int>(f.models.size()));
  ASSERT_TRUE(g.ok());
  auto rec = std::make_unique<TextureRecognizer>();
  const Status s = rec->Init(g->calib, *db, TextureRecognizerConfig{});
  EXPECT_EQ(s.code(), StatusCode::kDataLoss);
  EXPECT_NE(std::strstr(s.message(), "extraction settings"), nullptr) << s.message();
  EXPECT_NE(std::strstr(s.message(), "Harris k"), nullptr) << s.message();
}

}  // namespace
}  // namespace sh::texture
