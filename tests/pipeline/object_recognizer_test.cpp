// The recognition facade on rendered scenes: it reports what the stereo pipeline finds, tagged
// with the path, in the pipeline's own poses; the model mask selects what it reports; one
// camera without a table plane gives no poses; a missing path is refused at Init.
#include "recog/pipeline/object_recognizer.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <memory>

#include "recog/pipeline/recognition_paths.hpp"
#include "tests/support/rendered_fixture.hpp"

namespace sh {
namespace {

class ObjectRecognizerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    setup_ = testing::LoadRenderSetup(STEREOHASH_MODELS_DIR).release();
    ASSERT_NE(setup_, nullptr);
    table_ = &setup_->table;
    paths_ = MakeZeroed<RecognitionPaths>().release();
    ASSERT_TRUE(paths_->Allocate(/*printed=*/false, /*one_camera=*/true).ok());
    pair_ = new RenderedPair();
    const render::ScenarioParams p = testing::FourObjectScenario(render::Background::kDark);
    ASSERT_TRUE(RenderPair(21, p, setup_->models, pair_).ok());
  }
  static void TearDownTestSuite() {
    delete pair_;
    ZeroedDeleter<RecognitionPaths>()(paths_);
    delete setup_;
  }

  static ObjectRecognizerConfig OneThread() {
    ObjectRecognizerConfig config;
    config.automatic = false;  // the dark preset the scene is rendered for
    config.threads = 1;
    config.table_carry = false;
    return config;
  }
  static StereoInput Input() {
    return {FrameView::Gray(pair_->left_view()), FrameView::Gray(pair_->right_view()),
            pair_->left_view(), pair_->right_view()};
  }

  static testing::RenderSetup* setup_;
  static TableView* table_;
  static RecognitionPaths* paths_;
  static RenderedPair* pair_;
};

testing::RenderSetup* ObjectRecognizerTest::setup_ = nullptr;
TableView* ObjectRecognizerTest::table_ = nullptr;
RecognitionPaths* ObjectRecognizerTest::paths_ = nullptr;
RenderedPair* ObjectRecognizerTest::pair_ = nullptr;

// Every object the stereo pipeline accepted, with its pose and the weaker image's score, tagged
// as found by the polyhedral path.
TEST_F(ObjectRecognizerTest, ReportsThePipelinesObjectsTaggedWithThePath) {
  ObjectRecognizer recognizer(paths_->set(), OneThread());
  ASSERT_TRUE(recognizer.Init(pair_->generated.calib, ModelSet(table_, nullptr), ~0u).ok());
  auto out = std::make_unique<RecognitionOutput>();
  const Status s = recognizer.Process(Input(), 0, out.get());
  ASSERT_TRUE(s.ok()) << s.message();
  const PipelineResult& stereo = recognizer.stereo_result();
  ASSERT_GE(stereo.objects.size(), 2u);
  ASSERT_EQ(out->objects.size(), stereo.objects.size());
  EXPECT_FALSE(out->one_camera);
  for (size_t i = 0; i < out->objects.size(); ++i) {
    const FoundObject& o = out->objects[i];
    const RecognizedObject& r = stereo.objects[i];
    EXPECT_EQ(o.path, RecognitionPath::kPolyhedra);
    EXPECT_EQ(o.model, r.model);
    EXPECT_EQ(o.instance, r.instance);
    EXPECT_FLOAT_EQ(o.score, std::min(r.verify_score[0], r.verify_score[1]));
    EXPECT_EQ((o.cam_T_model.t_mm - r.cam_T_model.t_mm).norm(), 0.0f);
  }
  EXPECT_STREQ(RecognitionPathName(out->objects[0].path), "polyhedra");
}

// The mask leaves out the models whose bits are clear, and a changed mask takes effect at once.
TEST_F(ObjectRecognizerTest, TheModelMaskSelectsWhatIsReported) {
  ObjectRecognizer recognizer(paths_->set(), OneThread());
  ASSERT_TRUE(recognizer.Init(pair_->generated.calib, ModelSet(table_, nullptr), ~0u).ok());
  auto all = std::make_unique<RecognitionOutput>();
  ASSERT_TRUE(recognizer.Process(Input(), 0, all.get()).ok());
  ASSERT_FALSE(all->objects.empty());
  const uint32_t first = all->objects[0].model;
  ASSERT_TRUE(recognizer.SetModelMask(~(1u << first)).ok());
  auto masked = std::make_unique<RecognitionOutput>();
  ASSERT_TRUE(recognizer.Process(Input(), 0, masked.get()).ok());
  for (const FoundObject& o : masked->objects) EXPECT_NE(o.model, first);
  ASSERT_TRUE(recognizer.SetModelMask(1u << first).ok());
  ASSERT_TRUE(recognizer.Process(Input(), 0, masked.get()).ok());
  ASSERT_FALSE(masked->objects.empty());
  for (const FoundObject& o : masked->objects) EXPECT_EQ(o.model, first);
}

// One image cannot tell depth: without a configured table or a carried plane the fallback gives
// no poses and says why.
TEST_F(ObjectRecognizerTest, OneCameraWithoutATablePlaneIsRefused) {
  ObjectRecognizer recognizer(paths_->set(), OneThread());
  ASSERT_TRUE(recognizer.Init(pair_->generated.calib, ModelSet(table_, nullptr), ~0u).ok());
  EXPECT_TRUE(recognizer.monocular());
  auto out = std::make_unique<RecognitionOutput>();
  const Status s = recognizer.ProcessMonocular(0, pair_->left_view(), 0, out.get());
  EXPECT_EQ(s.code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(std::strstr(s.message(), kMonoNeedsTablePlane), nullptr) << s.message();
  EXPECT_TRUE(out->objects.empty());
}

// With the rendered table given, the fallback reports in the stereo tables' model ids, tagged as
// found by one camera, and the objects it finds are among those of the scene.
TEST_F(ObjectRecognizerTest, OneCameraOnAKnownTableReportsInTheStereoIds) {
  ObjectRecognizerConfig config = OneThread();
  config.mono_table_known = true;
  config.left_T_table = pair_->generated.scene.left_T_table;
  ObjectRecognizer recognizer(paths_->set(), config);
  ASSERT_TRUE(recognizer.Init(pair_->generated.calib, ModelSet(table_, nullptr), ~0u).ok());
  auto out = std::make_unique<RecognitionOutput>();
  const Status s = recognizer.ProcessMonocular(0, pair_->left_view(), 0, out.get());
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_TRUE(out->one_camera);
  ASSERT_FALSE(out->objects.empty());
  for (const FoundObject& o : out->objects) {
    EXPECT_EQ(o.path, RecognitionPath::kOneCamera);
    EXPECT_LT(o.model, table_->model_count());
  }
}

// A model set with printed models needs the texture path; a facade without the stereo pipeline
// is refused.
TEST_F(ObjectRecognizerTest, MissingPathsAreRefusedAtInit) {
  ObjectRecognizer no_stereo(RecognitionPathSet{}, OneThread());
  EXPECT_EQ(no_stereo.Init(pair_->generated.calib, ModelSet(table_, nullptr), ~0u).code(),
            StatusCode::kFailedPrecondition);
  RecognitionPathSet without_fallback = paths_->set();
  without_fallback.mono = nullptr;
  without_fallback.mono_result = nullptr;
  ObjectRecognizer stereo_only(without_fallback, OneThread());
  ASSERT_TRUE(stereo_only.Init(pair_->generated.calib, ModelSet(table_, nullptr), ~0u).ok());
  EXPECT_FALSE(stereo_only.monocular());
  auto out = std::make_unique<RecognitionOutput>();
  EXPECT_EQ(stereo_only.ProcessMonocular(0, pair_->left_view(), 0, out.get()).code(),
            StatusCode::kFailedPrecondition);
}

}  // namespace
}  // namespace sh
