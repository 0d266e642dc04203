// The whole pipeline on rendered stereo pairs with known poses: recognition quality against the
// ground truth, the stage bookkeeping, the budget, and the input errors.
#include "recog/pipeline/pipeline.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "tables/table_file.hpp"
#include "tests/support/rendered_fixture.hpp"
#include "tests/support/same_objects.hpp"
#include "tools/eval/rendered_eval.hpp"

namespace sh {
namespace {

int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

float Median(std::vector<float> v) {
  if (v.empty()) return 1e9f;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

class PipelineTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    setup_ = testing::LoadRenderSetup(STEREOHASH_MODELS_DIR).release();
    ASSERT_NE(setup_, nullptr);
    table_ = &setup_->table;
    models_ = &setup_->models;
    pipeline_ = new Pipeline();  // tens of MiB: one for the whole suite
  }
  static void TearDownTestSuite() {
    delete pipeline_;
    delete setup_;
  }

  static render::ScenarioParams Scenario(render::Background bg) {
    return testing::FourObjectScenario(bg);
  }

  // A dark-table scene with some occlusion; null (and a test failure) if it cannot be rendered.
  static std::unique_ptr<RenderedPair> RenderDark(uint64_t seed) {
    auto pair = std::make_unique<RenderedPair>();
    const Status s = RenderPair(seed, Scenario(render::Background::kDark), *models_, pair.get());
    if (!s.ok()) {
      ADD_FAILURE() << "seed " << seed << ": " << s.message();
      return nullptr;
    }
    return pair;
  }

  // Every case but SearchOnMoreThreadsGivesWhatOneGives runs on the calling thread alone: that
  // case shows two and three threads give what one gives, and it is the one the
  // ThreadSanitizer run takes (THREAD_CASES in CMakeLists.txt).
  static PipelineConfig OneThread(PipelineConfig config) {
    config.threads = 1;
    return config;
  }

  // Renders dark scene `seed`, runs the pipeline on it with `config` and points `verifier` at
  // the frame's edge maps; null (and a test failure) when that fails.
  static std::unique_ptr<RenderedPair> ProcessForVerifier(uint64_t seed,
                                                          const PipelineConfig& config,
                                                          EdgeMapVerifier& verifier) {
    std::unique_ptr<RenderedPair> pair = RenderDark(seed);
    if (pair == nullptr) return nullptr;
    PipelineResult result;
    if (!pipeline_->Init(pair->generated.calib, *table_, config, NowNs).ok() ||
        !pipeline_->Process(pair->left_view(), pair->right_view(), 0, &result).ok()) {
      ADD_FAILURE() << "seed " << seed << ": the pipeline did not run";
      return nullptr;
    }
    verifier.Reset(&pair->generated.calib, table_, pipeline_->left_edges(),
                   pipeline_->right_edges(), pipeline_->grey_evidence(0),
                   pipeline_->grey_evidence(1), &config.verify, nullptr, nullptr);
    return pair;
  }

  static PipelineConfig ConfigFor(render::Background bg) {
    return OneThread(bg == render::Background::kDark ? PipelineConfig::DarkBackground()
                                                     : PipelineConfig::LightBackground());
  }

  static testing::RenderSetup* setup_;
  static TableView* table_;
  static RenderModels* models_;
  static Pipeline* pipeline_;
};

testing::RenderSetup* PipelineTest::setup_ = nullptr;

TableView* PipelineTest::table_ = nullptr;
RenderModels* PipelineTest::models_ = nullptr;
Pipeline* PipelineTest::pipeline_ = nullptr;

// Most objects are found, few false alarms, and the poses of the correct ones are accurate.
TEST_F(PipelineTest, RecognisesRenderedScenes) {
  int objects = 0, correct = 0, false_alarms = 0, reported = 0;
  std::vector<float> t_err, r_err;
  auto pair = std::make_unique<RenderedPair>();
  PipelineResult result;
  for (render::Background bg : {render::Background::kDark, render::Background::kLight}) {
    for (uint64_t seed : {11u, 12u, 13u}) {
      ASSERT_TRUE(RenderPair(seed, Scenario(bg), *models_, pair.get()).ok());
      ASSERT_TRUE(pipeline_->Init(pair->generated.calib, *table_, ConfigFor(bg), NowNs).ok());
      const Status s = pipeline_->Process(pair->left_view(), pair->right_view(), 0, &result);
      ASSERT_TRUE(s.ok()) << s.message();
      const MatchCounts m = MatchToTruth(models_->table, pair->truth, PosesOf(result));
      objects += static_cast<int>(pair->truth.size());
      correct += m.correct;
      false_alarms += m.false_alarms;
      reported += static_cast<int>(result.objects.size());
      t_err.insert(t_err.end(), m.translation_errors_mm.begin(), m.translation_errors_mm.end());
      r_err.insert(r_err.end(), m.rotation_errors_deg.begin(), m.rotation_errors_deg.end());
      // Every accepted object passed verification in both images.
      for (const RecognizedObject& o : result.objects) {
        EXPECT_GE(o.verify_score[0], ConfigFor(bg).verify.min_fraction);
        EXPECT_GE(o.verify_score[1], ConfigFor(bg).verify.min_fraction);
        EXPECT_LE(o.verify_score[0], 1.0f);
        EXPECT_LE(o.verify_score[1], 1.0f);
      }
      EXPECT_GT(result.points2d[0], 0u);
      EXPECT_GT(result.lines2d[1], 0u);
      EXPECT_GT(result.lines3d, 0u);
    }
  }
  EXPECT_GE(correct, objects * 3 / 4) << correct << " of " << objects;
  EXPECT_LE(false_alarms, reported / 5) << false_alarms << " of " << reported;
  EXPECT_LT(Median(t_err), 2.0f);
  EXPECT_LT(Median(r_err), 2.0f);
}

// The verifier's faint-edge test reads the frame's grey images with their measured noise: the
// views it is given are the frame's own, and the noise is measured with a preset too (the
// renderer adds 1.5 grey levels).
TEST_F(PipelineTest, VerifierSeesTheFrameAndItsNoise) {
  const std::unique_ptr<RenderedPair> pair = RenderDark(14);
  ASSERT_NE(pair, nullptr);
  const PipelineConfig config = OneThread(PipelineConfig::DarkBackground());
  ASSERT_FALSE(config.features.adaptive);
  ASSERT_TRUE(config.verify.faint_edges);
  ASSERT_TRUE(pipeline_->Init(pair->generated.calib, *table_, config, NowNs).ok());
  PipelineResult result;
  ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, &result).ok());
  const ConstGrayView frames[2] = {pair->left_view(), pair->right_view()};
  for (int i = 0; i < 2; ++i) {
    const GreyEvidence grey = pipeline_->grey_evidence(i);
    EXPECT_EQ(grey.image.data, frames[i].data) << "image " << i;
    EXPECT_EQ(grey.image.width, frames[i].width);
    EXPECT_EQ(grey.image.height, frames[i].height);
    EXPECT_NEAR(grey.noise_sigma, 1.5f, 0.3f) << "image " << i;
    EXPECT_EQ(result.detection[i].noise_sigma, grey.noise_sigma);
  }
}

// The second look (PipelineConfig::second_look): true objects moved a millimetre or two off their
// outlines, which the verification's gate rejects in one image, pass after their fit to both
// images' edges and land within 1 mm / 1 deg of the truth; no other model at a true object's place
// passes that way.
TEST_F(PipelineTest, ASecondLookConfirmsAPoseAPixelOffAndNoWrongModel) {
  const PipelineConfig config = OneThread(PipelineConfig::Automatic());
  ASSERT_GT(config.second_look.floor, 0.0f);
  int rescued = 0, plain_accepted = 0, look_accepted = 0, wrong_plain = 0, wrong_look = 0,
      wrong_near = 0;
  for (uint64_t seed : {15u, 16u}) {
    EdgeMapVerifier verifier;
    const std::unique_ptr<RenderedPair> pair = ProcessForVerifier(seed, config, verifier);
    ASSERT_NE(pair, nullptr);
    const Vector<RecognizedObject, 1> none;
    // Verdicts without and with the second look.
    const auto verify = [&](const Model& model, const RigidTransform& pose, bool look,
                            RecognizedObject* candidate) {
      verifier.SetSecondLook(look ? config.second_look : SecondLook{}, config.edge_refine_config);
      candidate->cam_T_model = pose;
      return verifier.Verify(model, none, *candidate);
    };
    for (const TruthObject& truth : pair->truth) {
      const Model& model = table_->model(static_cast<uint32_t>(truth.model));
      for (const float shift_mm : {0.8f, 1.2f, 1.6f, 2.0f}) {
        for (const Eigen::Vector3f& axis : {Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(0, 1, 0)}) {
          RigidTransform moved = truth.cam_T_model;
          moved.t_mm += shift_mm * axis;
          RecognizedObject plain, looked;
          const bool accepted = verify(model, moved, false, &plain);
          const bool accepted_look = verify(model, moved, true, &looked);
          plain_accepted += accepted;
          look_accepted += accepted_look;
          EXPECT_TRUE(!accepted || accepted_look);  // a second look only adds
          if (accepted || !accepted_look) continue;
          ++rescued;
          EXPECT_LT((looked.cam_T_model.t_mm - truth.cam_T_model.t_mm).norm(), 1.0f);
          EXPECT_LT(SymmetricRotationErrorDeg(model, looked.cam_T_model.R, truth.cam_T_model.R),
                    1.0f);
          EXPECT_GE(std::min(looked.verify_score[0], looked.verify_score[1]),
                    config.second_look.strong);
        }
      }
      // Wrong hypotheses: other models at the true pose, and the true model turned by 8-30 deg
      // about its origin (beyond what the fit may turn, 3 deg).
      const auto wrong = [&](const Model& m, const RigidTransform& pose) {
        RecognizedObject plain, looked;
        const bool accepted = verify(m, pose, false, &plain);
        wrong_plain += accepted;
        wrong_look += verify(m, pose, true, &looked);
        // Rejected by a margin the second look takes up: the strong bar must keep it out.
        wrong_near += !accepted && std::min(plain.verify_score[0], plain.verify_score[1]) >=
                                       config.second_look.floor;
      };
      for (uint32_t other = 0; other < table_->model_count(); ++other) {
        if (static_cast<int>(other) != truth.model) wrong(table_->model(other), truth.cam_T_model);
      }
      for (const float turn_deg : {8.0f, 15.0f, 30.0f}) {
        for (const Eigen::Vector3f& axis : {Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(0, 0, 1)}) {
          RigidTransform turned = truth.cam_T_model;
          turned.R = Eigen::AngleAxisf(turn_deg * 3.14159265f / 180.0f, axis).toRotationMatrix() *
                     turned.R;
          wrong(model, turned);
        }
      }
    }
    EXPECT_GT(verifier.second_looks(), 0u);
  }
  std::printf(
      "moved true poses: %d accepted plainly, %d with the second look (%d rescued); "
      "wrong hypotheses: %d / %d accepted, %d near misses\n",
      plain_accepted, look_accepted, rescued, wrong_plain, wrong_look, wrong_near);
  EXPECT_GT(rescued, 0);
  EXPECT_GT(wrong_near, 0);  // the strong bar was put to the test
  EXPECT_EQ(wrong_look, wrong_plain);
}

// A true pose a millimetre or two off that passes with under half its samples in one image is
// fitted to the edge pixels too (SecondLook::refit_weak): it keeps its verdict, comes closer to
// the truth and is confirmed more in its weaker image. Hypotheses it rejects stay rejected.
TEST_F(PipelineTest, AWeaklyConfirmedPoseIsFittedToTheEdges) {
  const PipelineConfig config = OneThread(PipelineConfig::Automatic());
  ASSERT_TRUE(config.second_look.refit_weak);
  int weak = 0, refitted_closer = 0;
  for (uint64_t seed : {15u, 16u}) {
    EdgeMapVerifier verifier;
    const std::unique_ptr<RenderedPair> pair = ProcessForVerifier(seed, config, verifier);
    ASSERT_NE(pair, nullptr);
    const Vector<RecognizedObject, 1> none;
    SecondLook without = config.second_look;
    without.refit_weak = false;
    for (const TruthObject& truth : pair->truth) {
      const Model& model = table_->model(static_cast<uint32_t>(truth.model));
      for (const float shift_mm : {0.8f, 1.2f, 1.6f, 2.0f}) {
        for (const Eigen::Vector3f& axis : {Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(0, 1, 0)}) {
          RecognizedObject plain, refit;
          plain.cam_T_model = truth.cam_T_model;
          plain.cam_T_model.t_mm += shift_mm * axis;
          refit.cam_T_model = plain.cam_T_model;
          verifier.SetSecondLook(without, config.edge_refine_config);
          const bool accepted = verifier.Verify(model, none, plain);
          verifier.SetSecondLook(config.second_look, config.edge_refine_config);
          EXPECT_EQ(verifier.Verify(model, none, refit), accepted);
          const float plain_weaker = std::min(plain.verify_score[0], plain.verify_score[1]);
          if (!accepted || plain_weaker >= config.second_look.strong) continue;
          ++weak;
          EXPECT_GE(std::min(refit.verify_score[0], refit.verify_score[1]), plain_weaker);
          const float plain_mm = (plain.cam_T_model.t_mm - truth.cam_T_model.t_mm).norm();
          const float refit_mm = (refit.cam_T_model.t_mm - truth.cam_T_model.t_mm).norm();
          EXPECT_LE(refit_mm, plain_mm + 0.05f);
          refitted_closer += refit_mm < plain_mm - 0.2f;
        }
      }
    }
  }
  std::printf("weakly confirmed moved poses: %d, fitted closer to the truth: %d\n", weak,
              refitted_closer);
  EXPECT_GT(weak, 0);  // the rendered scenes hold the case
  EXPECT_GT(refitted_closer, 0);
}

// A wedge fits a cube's 40 x 30 side face and the edges beside it, and verifies at a good
// fraction of its own edges: the whole cube must win because it explains more edge pixels
// (`stereohash bench scenes --seed-offset 100000`, dark row with some occlusion, scene 102001,
// with the working volume over the table that the bench configures).
TEST_F(PipelineTest, WholeObjectWinsOverASmallerModelFittingPartOfIt) {
  render::ScenarioParams p = Scenario(render::Background::kDark);
  p.n_objects = 5;
  p.camera_distance_mm = 300.0f + 300.0f * 7.0f / 9.0f;
  auto pair = std::make_unique<RenderedPair>();
  ASSERT_TRUE(RenderPair(102001, p, *models_, pair.get()).ok());
  const int cube = table_->FindModel("cube");
  ASSERT_GE(cube, 0);
  ASSERT_TRUE(std::any_of(pair->truth.begin(), pair->truth.end(),
                          [&](const TruthObject& t) { return t.model == cube; }));
  PipelineConfig config = OneThread(PipelineConfig::DarkBackground());
  config.stereo.volume = WorkingVolume::InFrame(pair->generated.scene.left_T_table,
                                                Eigen::Vector3f(render::kTableVolumeMinMm),
                                                Eigen::Vector3f(render::kTableVolumeMaxMm));
  ASSERT_TRUE(pipeline_->Init(pair->generated.calib, *table_, config, NowNs).ok());
  PipelineResult result;
  ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, &result).ok());
  const MatchCounts m = MatchToTruth(models_->table, pair->truth, PosesOf(result));
  EXPECT_EQ(m.false_alarms, 0);
  bool cube_found = false;
  for (const RecognizedObject& o : result.objects) {
    const std::vector<RecognizedPose> one = {{o.model, o.cam_T_model}};
    cube_found |= o.model == cube && MatchToTruth(models_->table, pair->truth, one).correct == 1;
  }
  EXPECT_TRUE(cube_found);
}

TEST_F(PipelineTest, TimingsAddUpAndResultsRepeat) {
  std::unique_ptr<RenderedPair> pair = RenderDark(21);
  ASSERT_TRUE(pair);
  ASSERT_TRUE(
      pipeline_->Init(pair->generated.calib, *table_, ConfigFor(render::Background::kDark), NowNs)
          .ok());
  PipelineResult a, b;
  ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, &a).ok());
  ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, &b).ok());
  EXPECT_GT(a.time.features_ms, 0.0f);
  EXPECT_GT(a.time.stereo_ms, 0.0f);
  EXPECT_GT(a.time.hashing_ms, 0.0f);
  EXPECT_GE(a.time.verify_ms, 0.0f);
  EXPECT_GE(a.time.refine_ms, 0.0f);
  const float stages = a.time.features_ms + a.time.stereo_ms + a.time.hashing_ms +
                       a.time.verify_ms + a.time.refine_ms;
  EXPECT_LE(stages, a.time.total_ms * 1.001f + 0.01f);
  EXPECT_GE(stages, a.time.total_ms * 0.9f);
  EXPECT_FALSE(a.recognition.budget_exhausted);
  // Deterministic: the same frame gives the same objects.
  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (size_t i = 0; i < a.objects.size(); ++i) {
    EXPECT_EQ(a.objects[i].model, b.objects[i].model);
    EXPECT_TRUE(a.objects[i].cam_T_model.t_mm.isApprox(b.objects[i].cam_T_model.t_mm));
  }
  EXPECT_EQ(a.points3d, b.points3d);
  EXPECT_EQ(a.lines3d, b.lines3d);
}

// Every hypothesis the search tries, in order: basis number, model basis, vote, outcome, the
// refined pose's position and the verifier's evidence.
class HypothesisLog : public SearchObserver {
 public:
  struct Entry {
    uint32_t basis_number;
    uint32_t model_basis;
    float vote;
    Outcome outcome;
    Eigen::Vector3f t_mm;
    float evidence;
    bool operator==(const Entry& o) const {
      return basis_number == o.basis_number && model_basis == o.model_basis && vote == o.vote &&
             outcome == o.outcome && t_mm == o.t_mm && evidence == o.evidence;
    }
  };
  void OnHypothesis(uint32_t basis_number, const Hypothesis& h, const RecognizedObject& candidate,
                    Outcome outcome) override {
    entries.push_back({basis_number, h.model_basis, h.vote, outcome, candidate.cam_T_model.t_mm,
                       candidate.verify_evidence});
  }
  void OnAccepted(uint32_t, const RecognizedObject&) override { ++accepted; }
  std::vector<Entry> entries;
  int accepted = 0;
};

// The search votes scene bases ahead on the pool's threads (Recognizer::SetParallel), and
// refines and verifies the hypotheses of a basis together; each vote is made on the scene the
// one-thread search sees, and the hypotheses are taken in order, so two and three threads try
// the same hypotheses with the same votes, outcomes and refined poses in the same order as one
// and give exactly the same objects, also without a table (two searches) and on a light table.
TEST_F(PipelineTest, SearchOnMoreThreadsGivesWhatOneGives) {
  int compared = 0, accepted = 0;
  for (const render::Background bg : {render::Background::kDark, render::Background::kLight}) {
    for (const uint64_t seed : {41u, 42u}) {
      auto pair = std::make_unique<RenderedPair>();
      ASSERT_TRUE(RenderPair(seed, Scenario(bg), *models_, pair.get()).ok());
      PipelineResult result[3];
      HypothesisLog log[3];
      for (int threads = 1; threads <= 3; ++threads) {
        PipelineConfig config = PipelineConfig::Automatic();
        config.threads = threads;
        ASSERT_TRUE(pipeline_->Init(pair->generated.calib, *table_, config).ok());
        pipeline_->SetSearchObserver(&log[threads - 1]);
        const Status s =
            pipeline_->Process(pair->left_view(), pair->right_view(), 0, &result[threads - 1]);
        pipeline_->SetSearchObserver(nullptr);
        ASSERT_TRUE(s.ok()) << s.message();
      }
      EXPECT_TRUE(log[0].entries == log[1].entries) << "seed " << seed;
      EXPECT_TRUE(log[0].entries == log[2].entries) << "seed " << seed;
      EXPECT_EQ(result[0].objects.size(), result[2].objects.size());
      accepted += log[0].accepted;
      const PipelineResult &one = result[0], &two = result[1];
      EXPECT_EQ(one.recognition.scene_bases_tried, two.recognition.scene_bases_tried);
      EXPECT_EQ(one.recognition.hypotheses, two.recognition.hypotheses);
      testing::ExpectSameObjects(one.objects, two.objects, seed);
      compared += static_cast<int>(one.objects.size());
    }
  }
  EXPECT_GT(compared, 8);  // the scenes held objects to compare
  // Bases voted ahead of an accepted object were voted again: there were such objects.
  EXPECT_GT(accepted, 8);
}

TEST_F(PipelineTest, NoClockMeansNoTimings) {
  std::unique_ptr<RenderedPair> pair = RenderDark(22);
  ASSERT_TRUE(pair);
  ASSERT_TRUE(
      pipeline_->Init(pair->generated.calib, *table_, ConfigFor(render::Background::kDark)).ok());
  PipelineResult r;
  ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 1.0f, &r).ok());
  EXPECT_EQ(r.time.total_ms, 0.0f);
  EXPECT_FALSE(r.recognition.budget_exhausted);  // without a clock only the basis budget applies
  EXPECT_GT(r.objects.size(), 0u);
}

// RGB frames are converted into the pipeline's grey images; a pipeline set up without them
// (rgb_frames off: sources that always hand over a luma plane) refuses an RGB frame by name and
// still recognises grey frames, the same objects as the one with them.
TEST_F(PipelineTest, RgbFramesNeedTheGreyImagesAndAreRefusedWithoutThem) {
  std::unique_ptr<RenderedPair> pair = RenderDark(22);
  ASSERT_TRUE(pair);
  const FrameView grey[2] = {FrameView::Gray(pair->left_view()),
                             FrameView::Gray(pair->right_view())};
  std::vector<Rgb8> rgb[2];
  FrameView colour[2];
  for (int i = 0; i < 2; ++i) {
    const ConstGrayView& g = grey[i].luma;
    rgb[i].resize(static_cast<size_t>(g.width) * g.height);
    for (int y = 0; y < g.height; ++y) {
      for (int x = 0; x < g.width; ++x) {
        const uint8_t v = g.row(y)[x];
        rgb[i][static_cast<size_t>(y) * g.width + x] = {v, v, v};
      }
    }
    colour[i] = FrameView::Rgb({rgb[i].data(), g.width, g.height, g.width});
  }
  PipelineConfig config = ConfigFor(render::Background::kDark);
  PipelineResult with_rgb, from_grey;
  ASSERT_TRUE(pipeline_->Init(pair->generated.calib, *table_, config).ok());
  ASSERT_TRUE(pipeline_->Process(colour[0], colour[1], 0, &with_rgb).ok());
  EXPECT_GT(with_rgb.objects.size(), 0u);

  config.rgb_frames = false;
  ASSERT_TRUE(pipeline_->Init(pair->generated.calib, *table_, config).ok());
  PipelineResult refused;
  const Status s = pipeline_->Process(colour[0], colour[1], 0, &refused);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(s.message()).find("RGB"), std::string::npos) << s.message();
  ASSERT_TRUE(pipeline_->Process(grey[0], grey[1], 0, &from_grey).ok());
  ASSERT_EQ(from_grey.objects.size(), with_rgb.objects.size());
  for (size_t i = 0; i < from_grey.objects.size(); ++i) {
    EXPECT_EQ(from_grey.objects[i].model, with_rgb.objects[i].model);
    EXPECT_EQ(from_grey.objects[i].cam_T_model.t_mm, with_rgb.objects[i].cam_T_model.t_mm);
  }
}

// A budget shorter than the feature stage leaves no time for recognition: the frame completes
// with features and stereo but no objects, and says so.
TEST_F(PipelineTest, BudgetStopsRecognition) {
  std::unique_ptr<RenderedPair> pair = RenderDark(23);
  ASSERT_TRUE(pair);
  ASSERT_TRUE(
      pipeline_->Init(pair->generated.calib, *table_, ConfigFor(render::Background::kDark), NowNs)
          .ok());
  PipelineResult r;
  ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 1e-3f, &r).ok());
  EXPECT_TRUE(r.recognition.budget_exhausted);
  EXPECT_EQ(r.objects.size(), 0u);
  EXPECT_GT(r.lines3d, 0u);
}

TEST_F(PipelineTest, RefusesBadInput) {
  std::unique_ptr<RenderedPair> pair = RenderDark(26);
  ASSERT_TRUE(pair);
  PipelineResult r;
  {
    Pipeline* fresh = pipeline_;
    // Not initialised with a valid calibration: a clear precondition error.
    StereoCalibration broken = pair->generated.calib;
    broken.left.fx = -1;
    EXPECT_FALSE(fresh->Init(broken, *table_, OneThread(PipelineConfig{})).ok());
    const Status s = fresh->Process(pair->left_view(), pair->right_view(), 0, &r);
    EXPECT_EQ(s.code(), StatusCode::kFailedPrecondition) << s.message();
  }
  ASSERT_TRUE(
      pipeline_->Init(pair->generated.calib, *table_, OneThread(PipelineConfig{}), NowNs).ok());
  // Size mismatch with the calibration.
  ConstGrayView small = pair->left_view();
  small.width -= 4;
  Status s = pipeline_->Process(small, pair->right_view(), 0, &r);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(s.message()).find("calibration"), std::string::npos) << s.message();
  ConstGrayView short_right = pair->right_view();
  short_right.height -= 1;
  s = pipeline_->Process(pair->left_view(), short_right, 0, &r);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(s.message()).find("right"), std::string::npos) << s.message();
  // Empty images.
  s = pipeline_->Process(ConstGrayView{}, pair->right_view(), 0, &r);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(s.message()).find("empty"), std::string::npos) << s.message();
  EXPECT_EQ(r.objects.size(), 0u);
  // A bad configuration is refused at Init.
  PipelineConfig bad = OneThread(PipelineConfig{});
  bad.verify.min_fraction = 2.0f;
  EXPECT_FALSE(pipeline_->Init(pair->generated.calib, *table_, bad).ok());
  bad = OneThread(PipelineConfig{});
  bad.stereo.epipolar_tolerance_px = -1.0f;
  EXPECT_FALSE(pipeline_->Init(pair->generated.calib, *table_, bad).ok());
  bad = OneThread(PipelineConfig{});
  bad.second_look.floor = 1.5f;
  const Status look = pipeline_->Init(pair->generated.calib, *table_, bad);
  EXPECT_FALSE(look.ok());
  EXPECT_NE(std::string(look.message()).find("second look"), std::string::npos) << look.message();
}

// A camera larger than the buffers is refused at Init, naming both sizes; a pipeline without
// colour parts allocates no colour path.
TEST_F(PipelineTest, RefusesACameraLargerThanTheBuffersAndCarvesOnlyConfiguredPaths) {
  std::unique_ptr<RenderedPair> pair = RenderDark(27);
  ASSERT_TRUE(pair);
  StereoCalibration big = pair->generated.calib;
  big.left.width = big.right.width = kMaxImageWidth + 1;
  const Status s = pipeline_->Init(big, *table_, OneThread(PipelineConfig{}));
  EXPECT_EQ(s.code(), StatusCode::kOutOfRange) << s.message();
  EXPECT_NE(std::string(s.message()).find("1297x"), std::string::npos) << s.message();
  EXPECT_NE(std::string(s.message()).find("1296x1024"), std::string::npos) << s.message();
  ASSERT_TRUE(pipeline_->Init(pair->generated.calib, *table_, OneThread(PipelineConfig{})).ok());
  EXPECT_EQ(pipeline_->shape(), nullptr);
}

// The working volume is the stereo configuration's: with a box far behind the table, every 3-D
// feature that remains lies in that box (only spurious pairings can), and nothing is recognised.
TEST_F(PipelineTest, WorkingVolumeLimitsTheScene) {
  std::unique_ptr<RenderedPair> pair = RenderDark(25);
  ASSERT_TRUE(pair);
  PipelineConfig config = ConfigFor(render::Background::kDark);
  config.stereo.volume = WorkingVolume::InLeftCamera(Eigen::Vector3f(-500, -500, 2000),
                                                     Eigen::Vector3f(500, 500, 2500));
  ASSERT_TRUE(pipeline_->Init(pair->generated.calib, *table_, config).ok());
  PipelineResult r;
  ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, &r).ok());
  EXPECT_GT(r.points2d[0], 0u);
  EXPECT_EQ(r.objects.size(), 0u);
  const Scene& scene = pipeline_->scene();
  EXPECT_EQ(scene.points.size(), r.points3d);
  EXPECT_EQ(scene.lines.size(), r.lines3d);
  const auto inside = [](const Eigen::Vector3f& p) {
    return p.z() >= 2000.0f - 0.1f && p.z() <= 2500.0f + 0.1f && std::abs(p.x()) <= 500.1f &&
           std::abs(p.y()) <= 500.1f;
  };
  for (const ScenePoint& p : scene.points) EXPECT_TRUE(inside(p.p_mm));
  for (const SceneLine& l : scene.lines) {
    EXPECT_TRUE(inside(l.a_mm));
    EXPECT_TRUE(inside(l.b_mm));
  }
  // The same frame with the default volume does give objects.
  ASSERT_TRUE(
      pipeline_->Init(pair->generated.calib, *table_, ConfigFor(render::Background::kDark)).ok());
  ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, &r).ok());
  EXPECT_GT(r.objects.size(), 0u);
}

// Without a table the pipeline estimates it from the objects it finds standing on it, bounds the
// scene by it and says so; a given table is used as it is, and the estimate can be switched off.
TEST_F(PipelineTest, EstimatesTheTableTheObjectsStandOn) {
  PipelineResult r;
  int estimated = 0;
  for (uint64_t seed : {11u, 12u, 13u}) {
    std::unique_ptr<RenderedPair> pair = RenderDark(seed);
    ASSERT_TRUE(pair);
    const RigidTransform& truth = pair->generated.scene.left_T_table;
    ASSERT_TRUE(
        pipeline_->Init(pair->generated.calib, *table_, OneThread(PipelineConfig::Automatic()))
            .ok());
    ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, &r).ok());
    if (r.table_source != TableSource::kEstimated) continue;
    ++estimated;
    const TableEstimate& e = r.table_estimate;
    EXPECT_TRUE(e.accepted());
    EXPECT_GE(e.resting, 2u);
    const float normal_err_deg =
        std::acos(std::min(1.0f, e.left_T_table.R.col(2).dot(truth.R.col(2)))) * 57.29578f;
    EXPECT_LT(normal_err_deg, 1.0f) << "seed " << seed;
    EXPECT_NEAR(truth.R.col(2).dot(e.left_T_table.t_mm - truth.t_mm), 0.0f, 2.0f);
    EXPECT_GT(r.table_dropped, 0u);
    // The scene searched is the space over the estimated table.
    const Eigen::Vector3f up = e.left_T_table.R.col(2);
    const auto height = [&](const Eigen::Vector3f& p) { return up.dot(p - e.left_T_table.t_mm); };
    for (const ScenePoint& p : pipeline_->scene().points) {
      EXPECT_GE(height(p.p_mm), -kTableVolumeBelowMm - 0.01f);
      EXPECT_LE(height(p.p_mm), kTableVolumeHeightMm + 0.01f);
    }
    EXPECT_EQ(pipeline_->scene().lines.size(), r.lines3d);
    EXPECT_GT(r.objects.size(), 1u);
  }
  EXPECT_EQ(estimated, 3);

  std::unique_ptr<RenderedPair> pair = RenderDark(11);
  ASSERT_TRUE(pair);
  PipelineConfig given = OneThread(PipelineConfig::Automatic());
  given.table.known = true;
  given.table.left_T_table = pair->generated.scene.left_T_table;
  ASSERT_TRUE(pipeline_->Init(pair->generated.calib, *table_, given).ok());
  ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, &r).ok());
  EXPECT_EQ(r.table_source, TableSource::kGiven);
  EXPECT_EQ(r.table_estimate.outcome, TableEstimateOutcome::kDisabled);
  EXPECT_EQ(r.table_dropped, 0u);

  PipelineConfig off = OneThread(PipelineConfig::Automatic());
  off.table_estimate.enabled = false;
  ASSERT_TRUE(pipeline_->Init(pair->generated.calib, *table_, off).ok());
  ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, &r).ok());
  EXPECT_EQ(r.table_source, TableSource::kNone);
  EXPECT_EQ(r.table_estimate.outcome, TableEstimateOutcome::kDisabled);

  const PipelineResult without = r;

  // A refused estimate (more objects asked for than the scene has) after the shortened first
  // search gives exactly what no estimate gives: the search without a table runs to its end.
  PipelineConfig refused = OneThread(PipelineConfig::Automatic());
  refused.table_estimate.min_objects = 20;
  refused.table_estimate.first_search_objects = 2;  // the first search surely stops early
  ASSERT_TRUE(pipeline_->Init(pair->generated.calib, *table_, refused).ok());
  ASSERT_TRUE(pipeline_->Process(pair->left_view(), pair->right_view(), 0, &r).ok());
  EXPECT_EQ(r.table_source, TableSource::kNone);
  EXPECT_EQ(r.table_estimate.outcome, TableEstimateOutcome::kTooFewObjects);
  ASSERT_EQ(r.objects.size(), without.objects.size());
  ASSERT_GT(r.objects.size(), refused.table_estimate.first_search_objects);
  for (size_t i = 0; i < r.objects.size(); ++i) {
    EXPECT_EQ(r.objects[i].model, without.objects[i].model);
    EXPECT_LT((r.objects[i].cam_T_model.t_mm - without.objects[i].cam_T_model.t_mm).norm(), 1e-3f);
  }

  PipelineConfig bad = OneThread(PipelineConfig::Automatic());
  bad.table_estimate.tolerance_mm = -1;
  EXPECT_FALSE(pipeline_->Init(pair->generated.calib, *table_, bad).ok());
}

}  // namespace
}  // namespace sh
