// The monocular pipeline on four rendered scenes: objects found from one image with the table's
// pose, from either camera, and without a table. One process renders the scenes for all three
// tests (ctest runs the binary once).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <memory>
#include <thread>
#include <vector>

#include "recog/mono/mono_pipeline.hpp"
#include "recog/verify/inside_object.hpp"
#include "recog/verify/view_camera.hpp"
#include "tests/mono/mono_render.hpp"
#include "tests/support/same_objects.hpp"
#include "tools/eval/synthetic_scene.hpp"

namespace sh {
namespace {

using testing::FakeClock;
using testing::MonoScene;
using testing::MonoScenes;
using testing::MonoSceneSet;

struct Score {
  int objects = 0, correct = 0, reported = 0;
  std::vector<float> t_err, r_err;
};

void Add(const MonoSceneSet& f, const RenderedPair& pair, const MonoResult& r, float max_mm,
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

// Runs the one-camera pipeline over the test scenes from `camera` (0 left, 1 right), with each
// scene's table pose or (with_table false) without, scoring within max_mm; `check` sees every
// scene's result.
template <typename Check>
Score RunScenes(int camera, bool with_table, float max_mm, Check&& check) {
  const MonoSceneSet& f = MonoScenes();
  auto pipeline = std::make_unique<MonoPipeline>();
  auto workspace = MakeWorkspace<FeatureWorkspace>();
  auto result = std::make_unique<MonoResult>();
  Score score;
  for (int i = 0; i < testing::kMonoScenes; ++i) {
    const RenderedPair* pair = &MonoScene(i);
    const RigidTransform left_T_table = pair->generated.scene.left_T_table;
    const Status init =
        pipeline->Init(pair->generated.calib, camera, f.table, with_table ? &left_T_table : nullptr,
                       MonoPipelineConfig::Automatic(), FakeClock);
    EXPECT_TRUE(init.ok()) << init.message();
    if (!init.ok()) return score;
    const Status s = pipeline->Process(camera == 0 ? pair->left_view() : pair->right_view(), 0,
                                       *workspace, result.get());
    EXPECT_TRUE(s.ok()) << s.message();
    if (!s.ok()) return score;
    Add(f, *pair, *result, max_mm, &score);
    check(i, *pipeline, *result);
  }
  return score;
}

TEST(MonoPipeline, FindsRestingObjectsFromOneImageWithTheTable) {
  const MonoSceneSet& f = MonoScenes();
  const Score score =
      RunScenes(0, true, 5.0f, [&](int i, const MonoPipeline& pipeline, const MonoResult& result) {
        EXPECT_GT(result.time.total_ms, 0.0f);
        EXPECT_GE(result.time.total_ms, result.time.features_ms);
        for (const RecognizedObject& o : result.objects) {
          EXPECT_GE(o.verify_score[0], pipeline.config().mono.verify.min_fraction);
          EXPECT_GE(o.verify_score[1], pipeline.config().mono.min_match_fraction);
        }
        // One place, one object: no two reported objects hold each other's centre.
        for (size_t a = 0; a < result.objects.size(); ++a) {
          for (size_t b = a + 1; b < result.objects.size(); ++b) {
            const RecognizedObject& oa = result.objects[a];
            const RecognizedObject& ob = result.objects[b];
            EXPECT_FALSE(Interpenetrate({&f.table.model(oa.model), oa.cam_T_model},
                                        {&f.table.model(ob.model), ob.cam_T_model}))
                << "scene " << i << ": objects " << a << " and " << b;
          }
        }
      });
  EXPECT_GE(score.correct * 4, score.objects * 3) << score.correct << " of " << score.objects;
  EXPECT_LE((score.reported - score.correct) * 5, score.reported);
  // The table fixes depth and tilt: millimetre poses from one image.
  EXPECT_LT(Median(score.t_err), 1.0f);
  EXPECT_LT(Median(score.r_err), 1.0f);
}

TEST(MonoPipeline, RightCameraReportsPosesInTheLeftFrame) {
  const Score score = RunScenes(1, true, 5.0f, [](int, const MonoPipeline&, const MonoResult&) {});
  EXPECT_GE(score.correct * 4, score.objects * 3) << score.correct << " of " << score.objects;
}

TEST(MonoPipeline, WithoutTableThePosesAreFreeButCoarser) {
  const Score score =
      RunScenes(0, false, 15.0f, [](int, const MonoPipeline&, const MonoResult&) {});
  // Depth from one image without the table is the weak direction: within 15 mm for some.
  EXPECT_GT(score.correct, 0);
}

// A dark-table scene of five objects, none occluded (the generator's seed 1001, as `stereohash
// bench scenes --monocular` renders it: camera at 533 mm). Without the competing scene bases and
// the interpenetration rule a wrong model fitted to part of an object is accepted first and the
// object is missed; with them the right model takes that place.
TEST(MonoPipeline, OnePlaceOneObjectKeepsTheRightModel) {
  const MonoSceneSet& f = MonoScenes();
  render::ScenarioParams p;
  p.background = render::Background::kDark;
  p.occlusion = render::Occlusion::kNone;
  p.n_objects = 5;
  p.camera_distance_mm = 300.0f + 300.0f * 7.0f / 9.0f;
  p.spread_mm = 400.0f;
  auto pair = std::make_unique<RenderedPair>();
  ASSERT_TRUE(RenderPair(1001, p, f.models, pair.get()).ok());
  const RigidTransform left_T_table = pair->generated.scene.left_T_table;
  auto pipeline = std::make_unique<MonoPipeline>();
  auto workspace = MakeWorkspace<FeatureWorkspace>();
  auto result = std::make_unique<MonoResult>();
  Score with, without;
  MonoPipelineConfig config = MonoPipelineConfig::Automatic();
  ASSERT_TRUE(pipeline->Init(pair->generated.calib, 0, f.table, &left_T_table, config).ok());
  ASSERT_TRUE(pipeline->Process(pair->left_view(), 0, *workspace, result.get()).ok());
  Add(f, *pair, *result, 5.0f, &with);
  config.mono.competing_bases = 0;
  config.mono.exclude_interpenetrating = false;
  ASSERT_TRUE(pipeline->Init(pair->generated.calib, 0, f.table, &left_T_table, config).ok());
  ASSERT_TRUE(pipeline->Process(pair->left_view(), 0, *workspace, result.get()).ok());
  Add(f, *pair, *result, 5.0f, &without);
  EXPECT_GT(with.correct, without.correct);
  EXPECT_LE(with.reported - with.correct, without.reported - without.correct);
  EXPECT_EQ(with.correct, with.objects) << with.correct << " of " << with.objects;
}

// The image regions of the rest search: a disc around one point (the known object's image),
// or the whole image.
class DiscMask final : public FeatureMask {
 public:
  DiscMask(const Eigen::Vector2f& centre, float radius) : centre_(centre), radius_(radius) {}
  bool Hides(float x_px, float y_px) const override {
    return (Eigen::Vector2f(x_px, y_px) - centre_).norm() <= radius_;
  }
  uint32_t ClearEdges(EdgeMapView) const override { return 0; }

 private:
  Eigen::Vector2f centre_;
  float radius_;
};

// Sets the pipeline up for the scene's left camera and table, and processes its left image.
template <typename Workspace>
bool ProcessLeftWithTable(const RenderedPair& pair, MonoPipeline* pipeline, Workspace& workspace,
                          MonoResult* result) {
  const RigidTransform left_T_table = pair.generated.scene.left_T_table;
  return pipeline
             ->Init(pair.generated.calib, 0, MonoScenes().table, &left_T_table,
                    MonoPipelineConfig::Automatic(), FakeClock)
             .ok() &&
         pipeline->Process(pair.left_view(), 0, workspace, result).ok();
}

// The stereo pipeline's rescue: objects known before the search keep their place (never
// displaced, never found again), the others are found around them, and features the mask hides
// take no part.
TEST(MonoPipeline, RecognizeRestKeepsTheKnownObjectsAndFindsTheOthers) {
  const MonoSceneSet& f = MonoScenes();
  auto pipeline = std::make_unique<MonoPipeline>();
  auto workspace = MakeWorkspace<FeatureWorkspace>();
  auto result = std::make_unique<MonoResult>();
  const RenderedPair& pair = MonoScene(0);
  ASSERT_GE(pair.truth.size(), 2u);
  ASSERT_TRUE(ProcessLeftWithTable(pair, pipeline.get(), *workspace, result.get()));
  const TruthObject& known_truth = pair.truth[0];
  RecognizedObject known;
  known.model = static_cast<uint16_t>(known_truth.model);
  known.cam_T_model = known_truth.cam_T_model;
  known.verify_evidence = 1e9f;  // no candidate has more evidence
  const Eigen::Vector3f c = known.cam_T_model.t_mm;
  const CameraIntrinsics& cam = pair.generated.calib.left;
  const Eigen::Vector2f centre_px(static_cast<float>(cam.fx) * c.x() / c.z() + cam.cx,
                                  static_cast<float>(cam.fy) * c.y() / c.z() + cam.cy);
  const DiscMask around_known(centre_px, 1.0f);  // hides next to nothing
  Vector<RecognizedObject, kMaxObjects> objects;
  ASSERT_TRUE(objects.push_back(known));
  MonoStats stats;
  ASSERT_TRUE(pipeline->recognizer()
                  .RecognizeRest(pipeline->features(), around_known, Budget{}, objects, 1, &stats)
                  .ok());
  ASSERT_GE(objects.size(), 1u);
  EXPECT_EQ(objects[0].cam_T_model.t_mm, known.cam_T_model.t_mm);  // kept in first place
  for (size_t i = 1; i < objects.size(); ++i) {
    EXPECT_GT((objects[i].cam_T_model.t_mm - c).norm(), 15.0f) << "object " << i;
    EXPECT_FALSE(Interpenetrate({&f.table.model(objects[i].model), objects[i].cam_T_model},
                                {&f.table.model(known.model), known.cam_T_model}));
  }
  std::vector<TruthObject> others(pair.truth.begin() + 1, pair.truth.end());
  std::vector<RecognizedPose> found;
  for (size_t i = 1; i < objects.size(); ++i) {
    found.push_back({objects[i].model, objects[i].cam_T_model});
  }
  EXPECT_GT(MatchToTruth(f.models.table, others, found, 5.0f, 5.0f).correct, 0);

  // Every feature hidden: nothing but the known object.
  const DiscMask everything(centre_px, 1e6f);
  ASSERT_TRUE(pipeline->recognizer()
                  .RecognizeRest(pipeline->features(), everything, Budget{}, objects, 1, &stats)
                  .ok());
  EXPECT_EQ(objects.size(), 1u);
  EXPECT_EQ(stats.scene_bases_tried, 0u);
  // More known objects than the list holds is refused.
  EXPECT_FALSE(pipeline->recognizer()
                   .RecognizeRest(pipeline->features(), everything, Budget{}, objects, 2, &stats)
                   .ok());
}

// The stereo pipeline's rescue searches the right image with the recogniser set up for the left
// camera: set to the right camera it finds what one set up for the right camera finds (poses in
// the left camera's frame, the table where it was), and set back what it found before; a camera
// that is not above the table is refused with nothing changed.
TEST(MonoPipeline, SetCameraSearchesTheOtherImageAndSetsBack) {
  const MonoSceneSet& f = MonoScenes();
  auto left = std::make_unique<MonoPipeline>();
  auto right = std::make_unique<MonoPipeline>();
  // A workspace per image: the features' edge maps live in them.
  auto left_workspace = MakeWorkspace<FeatureWorkspace>();
  auto right_workspace = MakeWorkspace<FeatureWorkspace>();
  auto result = std::make_unique<MonoResult>();
  const RenderedPair& pair = MonoScene(0);
  const RigidTransform left_T_table = pair.generated.scene.left_T_table;
  const MonoPipelineConfig config = MonoPipelineConfig::Automatic();
  ASSERT_TRUE(left->Init(pair.generated.calib, 0, f.table, &left_T_table, config, FakeClock).ok());
  ASSERT_TRUE(right->Init(pair.generated.calib, 1, f.table, &left_T_table, config, FakeClock).ok());
  ASSERT_TRUE(right->Process(pair.right_view(), 0, *right_workspace, result.get()).ok());
  const Vector<RecognizedObject, kMaxObjects> in_right = result->objects;
  ASSERT_TRUE(left->Process(pair.left_view(), 0, *left_workspace, result.get()).ok());
  const Vector<RecognizedObject, kMaxObjects> in_left = result->objects;
  ASSERT_GT(in_right.size(), 0u);
  ASSERT_GT(in_left.size(), 0u);

  const auto expect_same = [](const Vector<RecognizedObject, kMaxObjects>& a,
                              const Vector<RecognizedObject, kMaxObjects>& b) {
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].model, b[i].model) << "object " << i;
      EXPECT_LT((a[i].cam_T_model.t_mm - b[i].cam_T_model.t_mm).norm(), 0.01f) << "object " << i;
      EXPECT_LT(RotationAngleDeg(a[i].cam_T_model.R.transpose() * b[i].cam_T_model.R), 0.01f);
    }
  };
  MonoRecognizer& recognizer = left->recognizer();
  Vector<RecognizedObject, kMaxObjects> objects;
  ASSERT_TRUE(recognizer.SetCamera(RightView(pair.generated.calib)).ok());
  ASSERT_TRUE(recognizer.Recognize(right->features(), Budget{}, objects).ok());
  expect_same(objects, in_right);
  ASSERT_TRUE(recognizer.SetCamera(LeftView(pair.generated.calib)).ok());
  ASSERT_TRUE(recognizer.Recognize(left->features(), Budget{}, objects).ok());
  expect_same(objects, in_left);

  // A camera in the table's plane (its frame the table's) is not above it: refused.
  ViewCamera on_table = LeftView(pair.generated.calib);
  on_table.cam_T_left = left_T_table.Inverse();
  EXPECT_FALSE(recognizer.SetCamera(on_table).ok());
  EXPECT_LT(
      (recognizer.camera().cam_T_left.t_mm - LeftView(pair.generated.calib).cam_T_left.t_mm).norm(),
      1e-6f);
  ASSERT_TRUE(recognizer.Recognize(left->features(), Budget{}, objects).ok());
  expect_same(objects, in_left);
}

// A ParallelFor whose calls beyond the first run on another thread, which counts them: the
// hypotheses of the slots beyond the first must be evaluated there, not on the caller.
//
// The other thread's calls end before the caller's starts. Calls that take the next job not yet
// taken would otherwise leave a worker that starts late (a loaded machine) nothing to do, and
// what a test asserts of the other thread's work would depend on the load. No call waits for
// another, so the order is one a pool may give too.
struct OtherThread {
  std::atomic<int> calls{0};

  ParallelFor Parallel() {
    ParallelFor parallel;
    parallel.pool = this;
    parallel.run = [](void* self, int n, void (*fn)(void*, int), void* context) {
      auto* other = static_cast<OtherThread*>(self);
      std::thread worker([&] {
        for (int i = 1; i < n; ++i) {
          fn(context, i);
          other->calls.fetch_add(1);
        }
      });
      worker.join();
      if (n > 0) fn(context, 0);
    };
    return parallel;
  }
};

// A search's counts, in one array to compare.
std::array<uint32_t, 12> Counts(const MonoStats& s) {
  return {s.scene_bases_available, s.scene_bases_tried, s.hypotheses,       s.rejected_tilt,
          s.rejected_depth,        s.rejected_matches,  s.rejected_overlap, s.verifications,
          s.rejected_verify,       s.accepted,          s.budget_exhausted, s.objects_full};
}

// One search of the rest (nothing hidden) after the known objects given: its objects and counts.
struct RestSearch {
  Vector<RecognizedObject, kMaxObjects> objects;
  MonoStats stats;
};
void SearchRest(MonoRecognizer& recognizer, const ImageFeatures& features,
                const RecognizedObject* known, RestSearch* out) {
  const DiscMask nothing_hidden(Eigen::Vector2f(-1e4f, -1e4f), 1.0f);
  out->objects.clear();
  if (known != nullptr) {
    ASSERT_TRUE(out->objects.push_back(*known));
  }
  const size_t n_known = known != nullptr ? 1 : 0;
  ASSERT_TRUE(
      recognizer
          .RecognizeRest(features, nothing_hidden, Budget{}, out->objects, n_known, &out->stats)
          .ok());
}

// Two searches' objects, counts and votes compared exactly.
void ExpectSameSearch(const RestSearch& a, const RestSearch& b, int scene) {
  testing::ExpectSameObjects(a.objects, b.objects, static_cast<uint64_t>(scene));
  EXPECT_EQ(Counts(a.stats), Counts(b.stats)) << "scene " << scene;
  EXPECT_EQ(a.stats.votes_digest, b.stats.votes_digest) << "scene " << scene;
}

// Runs `body(scene, pair, pipeline)` after the one-camera pipeline processed each test scene's
// left image with the table.
template <typename Body>
void ForEachLeftScene(Body&& body) {
  auto pipeline = std::make_unique<MonoPipeline>();
  auto workspace = MakeWorkspace<FeatureWorkspace>();
  auto result = std::make_unique<MonoResult>();
  for (int i = 0; i < testing::kMonoScenes; ++i) {
    const RenderedPair& pair = MonoScene(i);
    ASSERT_TRUE(ProcessLeftWithTable(pair, pipeline.get(), *workspace, result.get()));
    body(i, pair, *pipeline);
  }
}

// The stereo pipeline's rescue evaluates a scene basis's hypotheses on the pool's threads: with
// two threads, the search (whole, and around a known object) finds the same objects with the
// same counts as on the caller alone, and part of the work ran on the other thread.
TEST(MonoPipeline, HypothesesEvaluatedOnAnotherThreadChangeNothing) {
  OtherThread other;
  int found = 0;
  ForEachLeftScene([&](int i, const RenderedPair& pair, MonoPipeline& pipeline) {
    MonoRecognizer& recognizer = pipeline.recognizer();
    ASSERT_EQ(recognizer.evaluation_threads(), 1);
    ASSERT_GE(pair.truth.size(), 1u);
    RecognizedObject known;
    known.model = static_cast<uint16_t>(pair.truth[0].model);
    known.cam_T_model = pair.truth[0].cam_T_model;
    known.verify_evidence = 1e9f;
    const RecognizedObject* const knowns[] = {nullptr, &known};
    for (const RecognizedObject* k : knowns) {
      RestSearch serial, spread;
      ASSERT_TRUE(recognizer.SetParallel(ParallelFor{}, 1).ok());
      SearchRest(recognizer, pipeline.features(), k, &serial);
      ASSERT_TRUE(recognizer.SetParallel(other.Parallel(), 2).ok());
      ASSERT_EQ(recognizer.evaluation_threads(), 2);
      SearchRest(recognizer, pipeline.features(), k, &spread);
      ExpectSameSearch(serial, spread, i);
      found += static_cast<int>(serial.objects.size()) - (k != nullptr ? 1 : 0);
    }
    // A ParallelFor without a pool: the caller alone.
    ASSERT_TRUE(recognizer.SetParallel(ParallelFor{}, 2).ok());
    EXPECT_EQ(recognizer.evaluation_threads(), 1);
    EXPECT_FALSE(recognizer.SetParallel(ParallelFor{}, 0).ok());
  });
  EXPECT_GT(found, 0);
  EXPECT_GT(other.calls.load(), 0);
}

// With a second voter's counters lent (the stereo recogniser's idle vote scratch in the
// pipeline), the search votes the next scene bases over both voters: the same objects and counts
// as on the caller alone, with votes written into the lent block (filled with a pattern that
// only votes overwrite there), and a block too small refused with the votes left on the caller.
TEST(MonoPipeline, VotesInLentCountersChangeNothing) {
  OtherThread other;
  int found = 0;
  ForEachLeftScene([&](int i, const RenderedPair&, MonoPipeline& pipeline) {
    MonoRecognizer& recognizer = pipeline.recognizer();
    const size_t need = AspectVoter::CounterBytes(recognizer.table());
    std::vector<uint8_t> lent(need, 0xA5), small(need - 1, 0xA5);
    RestSearch serial, spread, refused;
    ASSERT_TRUE(recognizer.SetParallel(ParallelFor{}, 1).ok());
    ASSERT_TRUE(recognizer.LendVoteCounters(lent.data(), lent.size()).ok());
    EXPECT_FALSE(recognizer.votes_in_parallel());  // one evaluation thread: votes on the caller
    // Lending clears the stamps: the pattern left is what only votes overwrite.
    const auto pattern_left = [&] { return std::count(lent.begin(), lent.end(), uint8_t{0xA5}); };
    const auto after_lending = pattern_left();
    EXPECT_GT(after_lending, 0);
    SearchRest(recognizer, pipeline.features(), nullptr, &serial);
    EXPECT_EQ(pattern_left(), after_lending);

    ASSERT_TRUE(recognizer.SetParallel(other.Parallel(), 2).ok());
    ASSERT_TRUE(recognizer.LendVoteCounters(lent.data(), lent.size()).ok());
    EXPECT_TRUE(recognizer.votes_in_parallel());
    SearchRest(recognizer, pipeline.features(), nullptr, &spread);
    ExpectSameSearch(serial, spread, i);
    EXPECT_LT(pattern_left(), after_lending) << "scene " << i << ": the lent counters unused";

    EXPECT_EQ(recognizer.LendVoteCounters(small.data(), small.size()).code(),
              StatusCode::kResourceExhausted);
    EXPECT_FALSE(recognizer.votes_in_parallel());
    SearchRest(recognizer, pipeline.features(), nullptr, &refused);
    ExpectSameSearch(serial, refused, i);
    EXPECT_EQ(std::count(small.begin(), small.end(), uint8_t{0xA5}), static_cast<long>(need - 1));

    ASSERT_TRUE(recognizer.LendVoteCounters(nullptr, 0).ok());  // taken back
    EXPECT_FALSE(recognizer.votes_in_parallel());
    ASSERT_TRUE(recognizer.SetParallel(ParallelFor{}, 1).ok());
    found += static_cast<int>(serial.objects.size());
  });
  EXPECT_GT(found, 0);
}

// An acceptance removes the object's corners and lines from the scene: the bases voted ahead of
// it are voted again, since their votes may have counted those features. In this scene (six
// clustered objects on the light table, rendered from seed 108) a basis voted ahead counts a
// corner of the object accepted just before its turn, so its votes change; in most scenes the
// bases voted ahead lie beyond the accepted object's reach and keeping their votes would change
// nothing. The votes taken (MonoStats::votes_digest) equal the caller's alone.
TEST(MonoPipeline, VotesAheadOfAnAcceptanceAreVotedAgain) {
  OtherThread other;
  auto pair = std::make_unique<RenderedPair>();
  render::ScenarioParams clustered;
  clustered.n_objects = 6;
  clustered.background = render::Background::kLight;
  clustered.occlusion = render::Occlusion::kSevere;
  clustered.camera_distance_mm = 450.0f;
  ASSERT_TRUE(RenderPair(108, clustered, MonoScenes().models, pair.get()).ok());
  auto pipeline = std::make_unique<MonoPipeline>();
  auto workspace = MakeWorkspace<FeatureWorkspace>();
  auto result = std::make_unique<MonoResult>();
  ASSERT_TRUE(ProcessLeftWithTable(*pair, pipeline.get(), *workspace, result.get()));
  MonoRecognizer& recognizer = pipeline->recognizer();
  std::vector<uint8_t> lent(AspectVoter::CounterBytes(recognizer.table()));
  RestSearch serial, spread;
  ASSERT_TRUE(recognizer.SetParallel(ParallelFor{}, 1).ok());
  SearchRest(recognizer, pipeline->features(), nullptr, &serial);
  ASSERT_TRUE(recognizer.SetParallel(other.Parallel(), 2).ok());
  ASSERT_TRUE(recognizer.LendVoteCounters(lent.data(), lent.size()).ok());
  ASSERT_TRUE(recognizer.votes_in_parallel());
  SearchRest(recognizer, pipeline->features(), nullptr, &spread);
  ExpectSameSearch(serial, spread, 108);
  EXPECT_GE(serial.stats.accepted, 2u);  // acceptances with bases voted ahead of them
  ASSERT_TRUE(recognizer.LendVoteCounters(nullptr, 0).ok());
  ASSERT_TRUE(recognizer.SetParallel(ParallelFor{}, 1).ok());
}

}  // namespace
}  // namespace sh
