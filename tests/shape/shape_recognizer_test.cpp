// The shape path end to end on a flat-shaded stereo pair: a red cube, a red can and a green
// hexagon (two models share a colour, so the view search decides) are found with their model
// and pose, nothing is reported on an empty table, Process() never touches the heap, and the
// candidates refined on several threads give what one thread gives, also when every winner is
// refined again from turned starts.
#include "recog/shape/shape_recognizer.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "recog/shape/view_database.hpp"
#include "tests/shape/colour_view_blob.hpp"
#include "tests/shape/flat_scene.hpp"
#include "tests/shape/symmetric_angle.hpp"
#include "tests/support/counting_allocator.hpp"

namespace sh {
namespace {

constexpr const char* kNames[] = {"cube", "can", "hexagon"};
constexpr int kParts = 3;

using testing::SymmetricAngleDeg;

// Each part found once near its truth, as its own model, within 1 mm and 1 degree.
void ExpectEveryPartAtItsPose(const std::vector<testing::FlatPart>& parts,
                              const Vector<RecognizedObject, kMaxObjects>& found) {
  for (int i = 0; i < kParts; ++i) {
    const RecognizedObject* match = nullptr;
    for (const RecognizedObject& o : found) {
      if ((o.cam_T_model.t_mm - parts[i].posed.cam_T_model.t_mm).norm() < 20.0f) match = &o;
    }
    ASSERT_NE(match, nullptr) << kNames[i] << " not found";
    EXPECT_EQ(match->model, i) << kNames[i] << " reported as another model";
    EXPECT_LT((match->cam_T_model.t_mm - parts[i].posed.cam_T_model.t_mm).norm(), 1.0f)
        << kNames[i];
    EXPECT_LT(SymmetricAngleDeg(*parts[i].posed.model, match->cam_T_model.R,
                                parts[i].posed.cam_T_model.R),
              1.0f)
        << kNames[i];
  }
}

// A ParallelFor that runs every index on a thread of its own, all at once.
void RunOnThreads(void* /*pool*/, int n, void (*fn)(void* context, int index), void* context) {
  std::vector<std::thread> threads;
  threads.reserve(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) threads.emplace_back(fn, context, i);
  for (std::thread& t : threads) t.join();
}

// Process() on 1 to kMaxShapeThreads threads gives what one thread gives, bit for bit; returns
// the one thread's objects and statistics.
void ExpectSameOnEveryThreadCount(ShapeRecognizer& recognizer, const testing::FlatImage& left,
                                  const testing::FlatImage& right,
                                  Vector<RecognizedObject, kMaxObjects>* one_thread,
                                  ShapeStats* one_thread_stats) {
  ParallelFor on_threads;
  on_threads.run = &RunOnThreads;
  Vector<RecognizedObject, kMaxObjects> found[kMaxShapeThreads];
  ShapeStats stats[kMaxShapeThreads];
  for (int threads = 1; threads <= kMaxShapeThreads; ++threads) {
    recognizer.SetParallel(on_threads, threads);
    const Status s =
        recognizer.Process(left.frame(), right.frame(), found[threads - 1], &stats[threads - 1]);
    ASSERT_TRUE(s.ok()) << s.message();
  }
  for (int t = 1; t < kMaxShapeThreads; ++t) {
    EXPECT_EQ(stats[t].hypotheses, stats[0].hypotheses) << t + 1 << " threads";
    EXPECT_EQ(stats[t].verified, stats[0].verified) << t + 1 << " threads";
    EXPECT_EQ(stats[t].restarted, stats[0].restarted) << t + 1 << " threads";
    EXPECT_EQ(stats[t].restart_kept, stats[0].restart_kept) << t + 1 << " threads";
    ASSERT_EQ(found[t].size(), found[0].size()) << t + 1 << " threads";
    for (size_t i = 0; i < found[0].size(); ++i) {
      EXPECT_EQ(found[t][i].model, found[0][i].model);
      EXPECT_EQ(found[t][i].cam_T_model.t_mm, found[0][i].cam_T_model.t_mm);
      EXPECT_EQ(found[t][i].cam_T_model.R, found[0][i].cam_T_model.R);
      EXPECT_EQ(found[t][i].verify_evidence, found[0][i].verify_evidence);
    }
  }
  *one_thread = found[0];
  *one_thread_stats = stats[0];
}

class ShapeRecognizerTest : public ::testing::Test {
 protected:
  // One view database for every test (building it is the slow part).
  static void SetUpTestSuite() {
    blob_ = new std::vector<uint8_t>();
    ASSERT_NO_FATAL_FAILURE(
        testing::BuildColourViewBlob(std::vector<std::string>(kNames, kNames + kParts), blob_));
  }
  static void TearDownTestSuite() {
    delete blob_;
    blob_ = nullptr;
  }

  void SetUp() override {
    ASSERT_NE(blob_, nullptr);
    Result<ShapeViewsView> views = ShapeViewsView::Open(blob_->data(), blob_->size());
    ASSERT_TRUE(views.ok()) << views.status().message();
    views_ = *views;
    ASSERT_EQ(views_.model_count(), static_cast<uint32_t>(kParts));
    calib_ = testing::ThesisRig();
    recognizer_ = std::make_unique<ShapeRecognizer>();
    ASSERT_TRUE(recognizer_->Init(calib_, views_, ShapeConfig{}, 0).ok());
  }

  // The three parts apart from each other in both images, at generic orientations.
  std::vector<testing::FlatPart> Scene() const {
    const Eigen::Vector3f t_mm[kParts] = {{-85, -35, 460}, {-5, 55, 445}, {70, -40, 475}};
    const Eigen::Vector3f axes[kParts] = {
        {0.4f, -0.7f, 0.3f}, {1.0f, 0.2f, 0.1f}, {0.2f, 0.5f, 0.8f}};
    const float angles[kParts] = {2.1f, 1.2f, 0.9f};
    std::vector<testing::FlatPart> parts;
    for (int i = 0; i < kParts; ++i) {
      testing::FlatPart p;
      p.posed.model = &views_.model(static_cast<uint32_t>(i));
      p.posed.cam_T_model.R = Eigen::AngleAxisf(angles[i], axes[i].normalized()).toRotationMatrix();
      p.posed.cam_T_model.t_mm = t_mm[i];
      const float* kd = views_.shape_model(static_cast<uint32_t>(i)).kd;
      for (int k = 0; k < 3; ++k) p.kd[k] = kd[k];
      parts.push_back(p);
    }
    return parts;
  }

  // The scene of `parts` processed on 1 to kMaxShapeThreads threads, which must agree; the one
  // thread's objects and statistics.
  void ProcessOnEveryThreadCount(const std::vector<testing::FlatPart>& parts,
                                 Vector<RecognizedObject, kMaxObjects>* found, ShapeStats* stats) {
    testing::FlatImage left, right;
    testing::RenderFlatPair(calib_, parts, 40, 2.0f, &left, &right);
    ExpectSameOnEveryThreadCount(*recognizer_, left, right, found, stats);
  }

  static std::vector<uint8_t>* blob_;
  ShapeViewsView views_;
  StereoCalibration calib_;
  std::unique_ptr<ShapeRecognizer> recognizer_;
};

std::vector<uint8_t>* ShapeRecognizerTest::blob_ = nullptr;

TEST_F(ShapeRecognizerTest, FindsEveryPartWithItsModelAndPoseWithoutTouchingTheHeap) {
  const std::vector<testing::FlatPart> parts = Scene();
  testing::FlatImage left, right;
  testing::RenderFlatPair(calib_, parts, 40, 2.0f, &left, &right);
  Vector<RecognizedObject, kMaxObjects> found;
  ShapeStats stats;
  const uint64_t before = testing::HeapAllocations();
  const Status s = recognizer_->Process(left.frame(), right.frame(), found, &stats);
  EXPECT_EQ(testing::HeapAllocations(), before) << "Process() allocated";
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(found.size(), static_cast<size_t>(kParts));
  ExpectEveryPartAtItsPose(parts, found);
  EXPECT_FALSE(stats.regions_truncated || stats.pairs_truncated || stats.objects_full);
}

// One test for both, since every test process builds the view database again.
TEST_F(ShapeRecognizerTest, ReportsNothingOnAnEmptyTableAndRefusesFramesOfAnotherSize) {
  testing::FlatImage left, right;
  testing::RenderFlatPair(calib_, {}, 120, 2.0f, &left, &right);
  Vector<RecognizedObject, kMaxObjects> found;
  ShapeStats stats;
  ASSERT_TRUE(recognizer_->Process(left.frame(), right.frame(), found, &stats).ok());
  EXPECT_EQ(found.size(), 0u);
  EXPECT_EQ(stats.regions[0] + stats.regions[1], 0u);
  const FrameView small =
      FrameView::Rgb({left.rgb.data(), left.width / 2, left.height, left.width});
  EXPECT_EQ(recognizer_->Process(small, right.frame(), found, &stats).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(found.size(), 0u);
}

TEST_F(ShapeRecognizerTest, CandidatesRefinedOnSeveralThreadsGiveWhatOneThreadGives) {
  const std::vector<testing::FlatPart> parts = Scene();
  Vector<RecognizedObject, kMaxObjects> found;
  ShapeStats stats;
  ProcessOnEveryThreadCount(parts, &found, &stats);
  ASSERT_EQ(found.size(), static_cast<size_t>(kParts));
  // Several candidates per part were refined, so there was work to spread.
  EXPECT_GT(stats.hypotheses, 2u * kParts);
}

// Every winner counted as weak: each is refined again from six turned starts (on the threads),
// a start replaces it only with more evidence, so the parts keep their model and pose.
TEST_F(ShapeRecognizerTest, WinnersRefinedAgainFromTurnedStartsKeepTheirPoseOnEveryThreadCount) {
  ShapeConfig config;
  config.weak_edge_score = 1.0f;
  ASSERT_TRUE(recognizer_->Init(calib_, views_, config, 0).ok());
  const std::vector<testing::FlatPart> parts = Scene();
  Vector<RecognizedObject, kMaxObjects> found;
  ShapeStats stats;
  ProcessOnEveryThreadCount(parts, &found, &stats);
  ASSERT_EQ(found.size(), static_cast<size_t>(kParts));
  EXPECT_GE(stats.restarted, static_cast<uint32_t>(kParts));
  ExpectEveryPartAtItsPose(parts, found);
}

// Corrective iterations stopped once converged (the default) and all of them run (0 mm): the
// same parts, models and order, and poses that refinement takes to within a tenth of a
// millimetre and degree of each other.
TEST_F(ShapeRecognizerTest, ConvergedCorrectiveIterationsGiveWhatAllOfThemGive) {
  const std::vector<testing::FlatPart> parts = Scene();
  testing::FlatImage left, right;
  testing::RenderFlatPair(calib_, parts, 40, 2.0f, &left, &right);
  Vector<RecognizedObject, kMaxObjects> converged, all;
  ASSERT_TRUE(recognizer_->Process(left.frame(), right.frame(), converged, nullptr).ok());
  ShapeConfig config;
  config.corrective_converged_mm = 0.0f;
  ASSERT_TRUE(recognizer_->Init(calib_, views_, config, 0).ok());
  ASSERT_TRUE(recognizer_->Process(left.frame(), right.frame(), all, nullptr).ok());
  ExpectEveryPartAtItsPose(parts, all);
  ASSERT_EQ(converged.size(), all.size());
  for (size_t k = 0; k < all.size(); ++k) {
    const RecognizedObject& a = converged[k];
    const RecognizedObject& b = all[k];
    ASSERT_EQ(a.model, b.model) << "object " << k;
    EXPECT_LT((a.cam_T_model.t_mm - b.cam_T_model.t_mm).norm(), 0.1f) << kNames[a.model];
    EXPECT_LT(SymmetricAngleDeg(*parts[a.model].posed.model, a.cam_T_model.R, b.cam_T_model.R),
              0.1f)
        << kNames[a.model];
  }
}

TEST(ShapeConfigTest, RefusesRestartsAndSecondPassesOutOfRange) {
  EXPECT_TRUE(CheckShapeConfig(ShapeConfig{}).ok());
  ShapeConfig c;
  c.restart_deg = 91.0f;
  EXPECT_FALSE(CheckShapeConfig(c).ok());
  c = ShapeConfig{};
  c.weak_edge_score = 1.5f;
  EXPECT_FALSE(CheckShapeConfig(c).ok());
  c = ShapeConfig{};
  c.second_pass_starts = static_cast<int>(kMaxShapeCandidates) + 1;
  EXPECT_FALSE(CheckShapeConfig(c).ok());
  c = ShapeConfig{};
  c.second_pass_min_score = -0.1f;
  EXPECT_FALSE(CheckShapeConfig(c).ok());
  c = ShapeConfig{};
  c.corrective_converged_mm = -0.5f;
  EXPECT_FALSE(CheckShapeConfig(c).ok());
  c.corrective_converged_mm = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(CheckShapeConfig(c).ok());
}

}  // namespace
}  // namespace sh
