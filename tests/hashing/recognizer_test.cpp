#include "recog/hashing/recognizer.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <limits>
#include <string>

#include "tests/support/tables_fixture.hpp"

namespace sh {
namespace {

using testing::BuildTable;
using testing::MakeRecognizer;
using testing::ModelsOf;
using testing::Poses;

class RecognizerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto view = OpenDefaultTable();
    ASSERT_TRUE(view.ok());
    view_ = *view;
    models_ = ModelsOf(view_);
    synthetic_ = std::make_unique<SyntheticScene>();
  }
  // Each model alone in its scenes (`scenes` seeds from `seed_base` + 1000 x model), one
  // hypothesis per scene basis, competition over `compete_bases`: objects found correctly, and
  // objects of another model at the truth's place.
  struct CompetitionTally {
    int correct = 0, wrong_model_in_place = 0;
  };
  CompetitionTally RunAlone(SyntheticSceneParams p, int compete_bases, uint64_t seed_base,
                            int scenes) {
    RecognizerConfig config;
    config.hypotheses_per_basis = 1;
    config.compete_bases = compete_bases;
    auto recognizer = MakeRecognizer(view_, config);
    SceneSupportVerifier verifier(0.25f, 5);
    CompetitionTally t;
    for (int m = 0; m < int(models_.size()); ++m) {
      p.model_mask = 1u << m;
      for (int seed = 1; seed <= scenes; ++seed) {
        GenerateSyntheticScene(models_, p, seed_base + 1000 * uint64_t(m) + uint64_t(seed),
                               synthetic_.get());
        EXPECT_TRUE(recognizer->Recognize(synthetic_->scene, verifier, Budget{}, objects_).ok());
        const TruthObject& truth = synthetic_->truth[0];
        for (const RecognizedObject& o : objects_) {
          const bool in_place = (o.cam_T_model.t_mm - truth.cam_T_model.t_mm).norm() <
                                config.min_object_separation_mm;
          if (in_place && o.model != truth.model) ++t.wrong_model_in_place;
        }
        t.correct += MatchToTruth(models_, synthetic_->truth, Poses(objects_)).correct;
      }
    }
    return t;
  }

  // One object alone in its scene, a third to a half of its features lost, 1-1.5 mm noise.
  static SyntheticSceneParams OnePartlySeenObject() {
    SyntheticSceneParams p;
    p.min_objects = p.max_objects = 1;
    p.total_features = 0;
    p.missing_min = 0.3f;
    p.missing_max = 0.5f;
    p.noise_min_mm = 1.0f;
    p.noise_max_mm = 1.5f;
    return p;
  }

  TableView view_;
  std::vector<Model> models_;
  std::unique_ptr<SyntheticScene> synthetic_;
  Vector<RecognizedObject, kMaxObjects> objects_;
};

TEST_F(RecognizerTest, FindsEachModelAloneWithoutNoiseExactly) {
  auto recognizer = MakeRecognizer(view_);
  SyntheticSceneParams p;
  p.min_objects = p.max_objects = 1;
  p.noise_min_mm = p.noise_max_mm = 0.0f;
  p.missing_min = p.missing_max = 0.0f;
  p.total_features = 0;
  for (int m = 0; m < int(models_.size()); ++m) {
    p.model_mask = 1u << m;
    GenerateSyntheticScene(models_, p, 100 + m, synthetic_.get());
    SceneSupportVerifier verifier;
    ASSERT_TRUE(recognizer->Recognize(synthetic_->scene, verifier, Budget{}, objects_).ok());
    ASSERT_EQ(objects_.size(), 1u) << models_[m].name;
    EXPECT_EQ(objects_[0].model, m);
    const MatchCounts c = MatchToTruth(models_, synthetic_->truth, Poses(objects_), 0.05f, 0.05f);
    EXPECT_EQ(c.correct, 1) << models_[m].name;
  }
}

TEST_F(RecognizerTest, RecognisesClutteredMultiObjectScenes) {
  auto recognizer = MakeRecognizer(view_);
  SyntheticSceneParams p;
  p.total_features = 400;
  int correct = 0, truth = 0, false_alarms = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    GenerateSyntheticScene(models_, p, seed, synthetic_.get());
    SceneSupportVerifier verifier;
    ASSERT_TRUE(recognizer->Recognize(synthetic_->scene, verifier, Budget{}, objects_).ok());
    const MatchCounts c = MatchToTruth(models_, synthetic_->truth, Poses(objects_));
    correct += c.correct;
    false_alarms += c.false_alarms;
    truth += int(synthetic_->truth.size());
  }
  std::printf("hf5, 20 scenes x 400 features: %d of %d correct, %d false alarms\n", correct, truth,
              false_alarms);
  EXPECT_GE(correct, truth * 9 / 10);
  EXPECT_LE(false_alarms, truth / 20);
}

TEST_F(RecognizerTest, EveryHashFunctionRecognisesObjects) {
  SyntheticSceneParams p;
  p.min_objects = 2;
  p.max_objects = 3;
  p.total_features = 150;
  for (int hf = 1; hf <= 5; ++hf) {
    auto table = BuildTable(static_cast<HashFunction>(hf));
    auto recognizer = MakeRecognizer(table->view);
    int correct = 0, truth = 0;
    for (uint64_t seed = 1; seed <= 5; ++seed) {
      GenerateSyntheticScene(models_, p, seed, synthetic_.get());
      SceneSupportVerifier verifier;
      ASSERT_TRUE(recognizer->Recognize(synthetic_->scene, verifier, Budget{}, objects_).ok());
      correct += MatchToTruth(models_, synthetic_->truth, Poses(objects_)).correct;
      truth += int(synthetic_->truth.size());
    }
    std::printf("hf%d: %d of %d correct\n", hf, correct, truth);
    EXPECT_GE(correct, truth * 3 / 4) << "hash function " << hf;
  }
}

TEST_F(RecognizerTest, StopsWhenTheBudgetRunsOut) {
  auto recognizer = MakeRecognizer(view_);
  SyntheticSceneParams p;
  p.total_features = 600;
  GenerateSyntheticScene(models_, p, 7, synthetic_.get());
  SceneSupportVerifier verifier;
  Budget budget;
  budget.max_scene_bases = 1;
  RecognitionStats stats;
  ASSERT_TRUE(recognizer->Recognize(synthetic_->scene, verifier, budget, objects_, &stats).ok());
  EXPECT_EQ(stats.scene_bases_tried, 1u);
  EXPECT_TRUE(stats.budget_exhausted);
  EXPECT_LE(objects_.size(), 1u);

  // A deadline already in the past: nothing is tried, nothing is returned.
  budget.max_scene_bases = 1000;
  budget.deadline_ns = 1;
  budget.now_ns = [] { return int64_t{2}; };
  ASSERT_TRUE(recognizer->Recognize(synthetic_->scene, verifier, budget, objects_, &stats).ok());
  EXPECT_EQ(stats.scene_bases_tried, 0u);
  EXPECT_TRUE(stats.budget_exhausted);
  EXPECT_TRUE(objects_.empty());
}

// max_objects stops the search at that many accepted objects, before its fruitless tail.
TEST_F(RecognizerTest, StopsAtTheObjectLimit) {
  auto recognizer = MakeRecognizer(view_);
  SyntheticSceneParams p;
  p.min_objects = p.max_objects = 4;
  p.total_features = 300;
  GenerateSyntheticScene(models_, p, 11, synthetic_.get());
  SceneSupportVerifier verifier;
  RecognitionStats all, limited;
  ASSERT_TRUE(recognizer->Recognize(synthetic_->scene, verifier, Budget{}, objects_, &all).ok());
  ASSERT_GE(objects_.size(), 3u);
  Budget budget;
  budget.max_objects = 2;
  ASSERT_TRUE(recognizer->Recognize(synthetic_->scene, verifier, budget, objects_, &limited).ok());
  EXPECT_EQ(objects_.size(), 2u);
  EXPECT_LT(limited.scene_bases_tried, all.scene_bases_tried);
  EXPECT_FALSE(limited.budget_exhausted);
}

// Settings of the bases' spread over the scene that would make the cell arithmetic meaningless
// are refused at Init, by name.
TEST_F(RecognizerTest, RefusesCellSpreadSettingsOutOfRange) {
  const float bad[][2] = {{-1.0f, 50.0f},
                          {0.5f, 0.0f},
                          {0.5f, -50.0f},
                          {0.5f, 0.1f},
                          {0.5f, std::numeric_limits<float>::quiet_NaN()},
                          {std::numeric_limits<float>::infinity(), 50.0f}};
  for (const auto& b : bad) {
    RecognizerConfig config;
    config.basis_cell_rank_penalty = b[0];
    config.basis_cell_size_mm = b[1];
    auto recognizer = std::make_unique<Recognizer>();
    const Status s = recognizer->Init(view_, config);
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument) << b[0] << " " << b[1];
    EXPECT_NE(std::string(s.message()).find("cell"), std::string::npos) << s.message();
  }
  RecognizerConfig good;
  good.basis_cell_rank_penalty = 0.5f;
  good.basis_cell_size_mm = 50.0f;
  EXPECT_TRUE(std::make_unique<Recognizer>()->Init(view_, good).ok());
}

// Competition margins outside 0..1 (or not numbers) are refused at Init, by name.
TEST_F(RecognizerTest, RefusesCompetitionMarginsOutOfRange) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float bad[][2] = {{-0.1f, 0.05f}, {0.1f, -0.01f}, {1.5f, 0.05f}, {0.1f, nan}, {nan, 0.05f}};
  for (const auto& b : bad) {
    RecognizerConfig config;
    config.compete_evidence_margin = b[0];
    config.compete_score_margin = b[1];
    const Status s = std::make_unique<Recognizer>()->Init(view_, config);
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument) << b[0] << " " << b[1];
    EXPECT_NE(std::string(s.message()).find("competition margins"), std::string::npos)
        << s.message();
  }
  RecognizerConfig zero;
  zero.compete_evidence_margin = zero.compete_score_margin = 0.0f;
  EXPECT_TRUE(std::make_unique<Recognizer>()->Init(view_, zero).ok());
  // The challengers' vote factor in (0, 1], their extra matches not negative.
  const float bad_factors[] = {0.0f, -0.5f, 1.5f, nan};
  for (const float factor : bad_factors) {
    RecognizerConfig config;
    config.compete_vote_factor = factor;
    const Status s = std::make_unique<Recognizer>()->Init(view_, config);
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument) << factor;
    EXPECT_NE(std::string(s.message()).find("competition vote factor"), std::string::npos)
        << s.message();
  }
  RecognizerConfig negative;
  negative.compete_extra_matches = -1;
  EXPECT_EQ(std::make_unique<Recognizer>()->Init(view_, negative).code(),
            StatusCode::kInvalidArgument);
  RecognizerConfig lowest;
  lowest.compete_vote_factor = 0.1f;
  lowest.compete_extra_matches = 0;
  EXPECT_TRUE(std::make_unique<Recognizer>()->Init(view_, lowest).ok());
}

TEST_F(RecognizerTest, HonoursTheModelMask) {
  RecognizerConfig config;
  config.model_mask = ~(1u << 0);  // everything but the cube
  auto recognizer = MakeRecognizer(view_, config);
  SyntheticSceneParams p;
  p.min_objects = p.max_objects = 1;
  p.model_mask = 1u << 0;
  p.total_features = 100;
  GenerateSyntheticScene(models_, p, 3, synthetic_.get());
  SceneSupportVerifier verifier;
  ASSERT_TRUE(recognizer->Recognize(synthetic_->scene, verifier, Budget{}, objects_).ok());
  for (const RecognizedObject& o : objects_) EXPECT_NE(o.model, 0);
}

// A verifier that rejects everything: nothing is reported, and the search tries every basis.
class RejectAll : public HypothesisVerifier {
 public:
  bool Verify(const Model&, const Vector<RecognizedObject>&, RecognizedObject&) override {
    ++calls;
    return false;
  }
  int calls = 0;
};

TEST_F(RecognizerTest, ReportsOnlyVerifiedObjects) {
  auto recognizer = MakeRecognizer(view_);
  SyntheticSceneParams p;
  p.min_objects = p.max_objects = 2;
  p.total_features = 100;
  GenerateSyntheticScene(models_, p, 11, synthetic_.get());
  RejectAll verifier;
  RecognitionStats stats;
  ASSERT_TRUE(recognizer->Recognize(synthetic_->scene, verifier, Budget{}, objects_, &stats).ok());
  EXPECT_TRUE(objects_.empty());
  EXPECT_GT(verifier.calls, 0);
  EXPECT_EQ(stats.verifications, uint32_t(verifier.calls));
  EXPECT_FALSE(stats.budget_exhausted);
}

// The observer sees every verified, rejected or too-close hypothesis and every acceptance, in the
// order of the scene bases tried; without one the result is the same.
TEST_F(RecognizerTest, ObserverSeesEveryHypothesisAndAcceptance) {
  class Recorder : public SearchObserver {
   public:
    void OnHypothesis(uint32_t basis_number, const Hypothesis&, const RecognizedObject&,
                      Outcome outcome) override {
      EXPECT_GE(basis_number, last_basis);
      last_basis = basis_number;
      ++hypotheses;
      verified += outcome == Outcome::kVerified;
      checked += outcome != Outcome::kTooClose;
    }
    void OnAccepted(uint32_t basis_number, const RecognizedObject& object) override {
      EXPECT_EQ(basis_number, last_basis);
      accepted.push_back(object.model);
    }
    uint32_t last_basis = 0;
    int hypotheses = 0, verified = 0, checked = 0;
    std::vector<int> accepted;
  };
  auto recognizer = MakeRecognizer(view_);
  SyntheticSceneParams p;
  p.min_objects = p.max_objects = 3;
  p.total_features = 200;
  GenerateSyntheticScene(models_, p, 21, synthetic_.get());
  SceneSupportVerifier verifier;
  RecognitionStats plain;
  ASSERT_TRUE(recognizer->Recognize(synthetic_->scene, verifier, Budget{}, objects_, &plain).ok());
  const std::vector<RecognizedPose> without = Poses(objects_);

  Recorder recorder;
  recognizer->SetObserver(&recorder);
  RecognitionStats stats;
  ASSERT_TRUE(recognizer->Recognize(synthetic_->scene, verifier, Budget{}, objects_, &stats).ok());
  recognizer->SetObserver(nullptr);
  ASSERT_FALSE(objects_.empty());
  EXPECT_EQ(uint32_t(recorder.checked), stats.verifications);
  EXPECT_GE(recorder.hypotheses, recorder.checked);
  EXPECT_GE(recorder.verified, int(objects_.size()));
  ASSERT_EQ(recorder.accepted.size(), objects_.size());
  for (size_t i = 0; i < objects_.size(); ++i) EXPECT_EQ(recorder.accepted[i], objects_[i].model);
  EXPECT_EQ(stats.verifications, plain.verifications);
  ASSERT_EQ(without.size(), objects_.size());
  for (size_t i = 0; i < objects_.size(); ++i) {
    EXPECT_TRUE(without[i].cam_T_model.t_mm.isApprox(objects_[i].cam_T_model.t_mm));
  }
}

// Competition at acceptance: a model fitting a subset of an object's corners and edges may be
// voted best on the first scene basis and accepted; the next bases at its place then show the
// object's own model, which explains clearly more and replaces it. Each model alone in its
// scene, one hypothesis per scene basis (so that the object's own model cannot win within the
// basis that found the smaller one).
TEST_F(RecognizerTest, CompetitionAtAcceptanceReplacesAModelFittingPartOfAnother) {
  SyntheticSceneParams p = OnePartlySeenObject();
  const CompetitionTally without = RunAlone(p, 0, 0, 30), with = RunAlone(p, 5, 0, 30);
  std::printf("competition off: %d correct, %d wrong models in place; on: %d, %d\n",
              without.correct, without.wrong_model_in_place, with.correct,
              with.wrong_model_in_place);
  ASSERT_GT(without.wrong_model_in_place, 0);  // the scenes hold the case
  EXPECT_LT(with.wrong_model_in_place, without.wrong_model_in_place);
  EXPECT_GT(with.correct, without.correct);
}

// The competition's test on verification figures: clearly more evidence may come with a score a
// little lower in one image; as much evidence needs both scores higher.
TEST(ChallengerClearlyBetterTest, WantsMoreEvidenceOrBetterScoresInBothImages) {
  RecognizerConfig config;  // margins 0.1 (evidence) and 0.05 (scores)
  auto object = [](float left, float right, float evidence) {
    RecognizedObject o;
    o.verify_score[0] = left;
    o.verify_score[1] = right;
    o.verify_evidence = evidence;
    return o;
  };
  const RecognizedObject part = object(0.78f, 0.61f, 942.0f);
  // A hexagon prism seen whole under noise against a trapezium prism fitted to half of it: a
  // little less evidence, both shares higher.
  EXPECT_TRUE(ChallengerClearlyBetter(object(0.83f, 0.71f, 927.0f), part, config));
  // ... but not with one share lower, nor with clearly less evidence.
  EXPECT_FALSE(ChallengerClearlyBetter(object(0.77f, 0.80f, 927.0f), part, config));
  EXPECT_FALSE(ChallengerClearlyBetter(object(0.83f, 0.71f, 840.0f), part, config));
  // Clearly more evidence: one share may be lower by the score margin, not more.
  EXPECT_TRUE(ChallengerClearlyBetter(object(0.74f, 0.76f, 1040.0f), part, config));
  EXPECT_FALSE(ChallengerClearlyBetter(object(0.72f, 0.80f, 1040.0f), part, config));
  // Never without both shares together higher by twice the score margin.
  EXPECT_FALSE(ChallengerClearlyBetter(object(0.80f, 0.65f, 2000.0f), part, config));
  EXPECT_FALSE(ChallengerClearlyBetter(part, part, config));
}

// The same in a crowded volume: clutter around the object gives its place more scene bases than
// the competition scans after the accepted basis, so the object's own model is found only from
// bases made of the features the wrong model matched, wherever they rank.
TEST_F(RecognizerTest, CompetitionReachesTheObjectsOwnBasesBehindClutter) {
  SyntheticSceneParams p = OnePartlySeenObject();
  p.total_features = 800;
  p.volume_min_mm = Eigen::Vector3f(-60.0f, -60.0f, 500.0f);
  p.volume_max_mm = Eigen::Vector3f(60.0f, 60.0f, 570.0f);
  const int without = RunAlone(p, 0, 7000, 20).wrong_model_in_place;
  const int with = RunAlone(p, 5, 7000, 20).wrong_model_in_place;
  std::printf("crowded: wrong models in place, competition off %d, on %d\n", without, with);
  ASSERT_GT(without, 0);  // the scenes hold the case
  EXPECT_LT(with, without);
}

// Scores a candidate at the truth's place with the truth's model strongly and anything else
// weakly (SceneSupportVerifier's verdict): a wrong model or pose confirmed by part of an object.
class TruthScoringVerifier : public HypothesisVerifier {
 public:
  explicit TruthScoringVerifier(const std::vector<TruthObject>* truth) : truth_(truth) {}
  bool Verify(const Model& model, const Vector<RecognizedObject>& accepted,
              RecognizedObject& candidate) override {
    if (!support_.Verify(model, accepted, candidate)) return false;
    bool strong = false;
    for (const TruthObject& t : *truth_) {
      strong = strong || (t.model == candidate.model &&
                          (t.cam_T_model.t_mm - candidate.cam_T_model.t_mm).norm() < 5.0f);
    }
    const float score = strong ? 0.9f : 0.46f;
    candidate.verify_score[0] = candidate.verify_score[1] = score;
    candidate.verify_evidence = score;
    return true;
  }

 private:
  const std::vector<TruthObject>* truth_;
  SceneSupportVerifier support_{0.25f, 5};
};

// Held back, a weakly confirmed wrong model or pose leaves the object's features in the scene:
// the object's own scene bases, later in the list, find it with clearly more support, and the
// weak one, standing in its place, is dropped when the search ends. Each model alone in its
// scene, one hypothesis per scene basis and no competition, so that nothing else replaces it.
TEST_F(RecognizerTest, WeakConfirmationsWaitForTheStrongOnes) {
  SyntheticSceneParams p = OnePartlySeenObject();
  struct Tally {
    int correct = 0, wrong_in_place = 0;
    uint32_t deferred = 0, deferred_accepted = 0;
  };
  const auto run = [&](float defer_below_score) {
    RecognizerConfig config;
    config.hypotheses_per_basis = 1;
    config.defer_below_score = defer_below_score;
    auto recognizer = MakeRecognizer(view_, config);
    Tally t;
    for (int m = 0; m < int(models_.size()); ++m) {
      p.model_mask = 1u << m;
      for (uint64_t seed = 1; seed <= 30; ++seed) {
        GenerateSyntheticScene(models_, p, 1000 * uint64_t(m) + seed, synthetic_.get());
        TruthScoringVerifier verifier(&synthetic_->truth);
        RecognitionStats stats;
        EXPECT_TRUE(
            recognizer->Recognize(synthetic_->scene, verifier, Budget{}, objects_, &stats).ok());
        const TruthObject& truth = synthetic_->truth[0];
        for (const RecognizedObject& o : objects_) {
          const bool in_place = (o.cam_T_model.t_mm - truth.cam_T_model.t_mm).norm() <
                                config.min_object_separation_mm;
          t.wrong_in_place += in_place && o.verify_score[0] < 0.5f;
        }
        t.correct += MatchToTruth(models_, synthetic_->truth, Poses(objects_)).correct;
        t.deferred += stats.deferred;
        t.deferred_accepted += stats.deferred_accepted;
      }
    }
    return t;
  };
  const Tally now = run(0.0f), later = run(0.5f);
  std::printf(
      "weak confirmations accepted at once: %d correct, %d wrong in place; held back: "
      "%d, %d (%u held, %u accepted)\n",
      now.correct, now.wrong_in_place, later.correct, later.wrong_in_place, later.deferred,
      later.deferred_accepted);
  ASSERT_GT(now.wrong_in_place, 0);  // the scenes hold the case
  EXPECT_EQ(now.deferred, 0u);
  EXPECT_GT(later.deferred, 0u);
  EXPECT_LT(later.wrong_in_place, now.wrong_in_place);
  EXPECT_GT(later.correct, now.correct);
  // Where no strong object stands, a held-back one is still reported.
  EXPECT_GT(later.deferred_accepted, 0u);
}

// Accepts whatever holds three matched corners and edges, weakly, and reports every candidate
// as passing through the objects accepted before it when asked to.
class AcceptAllWeakly : public HypothesisVerifier {
 public:
  explicit AcceptAllWeakly(bool solid) : solid_(solid) {}
  bool Verify(const Model&, const Vector<RecognizedObject>&, RecognizedObject& c) override {
    c.verify_score[0] = c.verify_score[1] = 0.3f;
    c.verify_evidence = float(c.matched_points + c.matched_lines);
    return c.matched_points >= 3 && c.matched_lines >= 3;
  }
  bool Interpenetrates(const Model&, const RecognizedObject&,
                       const Vector<RecognizedObject>& accepted) const override {
    return solid_ && !accepted.empty();
  }

 private:
  bool solid_;
};

// More weak places than kMaxDeferredObjects: the strongest are kept and reported; a verifier
// that finds every place taken admits only the first.
TEST_F(RecognizerTest, HeldBackObjectsAreBoundedAndYieldToOccupiedPlaces) {
  RecognizerConfig config;
  config.defer_below_score = 0.5f;
  config.max_fruitless_bases = 800;
  config.min_object_separation_mm = 4.0f;  // more places apart
  auto recognizer = MakeRecognizer(view_, config);
  SyntheticSceneParams p;
  p.total_features = 1000;
  GenerateSyntheticScene(models_, p, 21, synthetic_.get());
  AcceptAllWeakly open(false), solid(true);
  RecognitionStats stats;
  ASSERT_TRUE(recognizer->Recognize(synthetic_->scene, open, Budget{}, objects_, &stats).ok());
  ASSERT_GT(stats.deferred, kMaxDeferredObjects) << "the scene must hold the case";
  EXPECT_EQ(stats.deferred_accepted, objects_.size());
  EXPECT_EQ(stats.accepted, objects_.size());
  EXPECT_LE(objects_.size(), kMaxDeferredObjects);
  EXPECT_GT(objects_.size(), 1u);
  // Strongest first.
  for (size_t i = 1; i < objects_.size(); ++i) {
    EXPECT_GE(objects_[i - 1].verify_evidence, objects_[i].verify_evidence);
  }
  ASSERT_TRUE(recognizer->Recognize(synthetic_->scene, solid, Budget{}, objects_, &stats).ok());
  EXPECT_EQ(objects_.size(), 1u);
  // The object limit holds for them too.
  Budget two;
  two.max_objects = 2;
  ASSERT_TRUE(recognizer->Recognize(synthetic_->scene, open, two, objects_, &stats).ok());
  EXPECT_EQ(objects_.size(), 2u);
}

TEST_F(RecognizerTest, RefusesADeferralScoreOutOfRange) {
  for (const float bad : {-0.1f, 1.5f, std::numeric_limits<float>::quiet_NaN()}) {
    RecognizerConfig config;
    config.defer_below_score = bad;
    const Status s = std::make_unique<Recognizer>()->Init(view_, config);
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument) << bad;
    EXPECT_NE(std::string(s.message()).find("defer_below_score"), std::string::npos);
  }
}

// Removing an object takes every 3-D feature that shares a 2-D feature with it.
TEST_F(RecognizerTest, RemovesFeaturesSharingTwoDimensionalSources) {
  auto recognizer = MakeRecognizer(view_);
  SyntheticSceneParams p;
  p.min_objects = p.max_objects = 1;
  p.noise_min_mm = p.noise_max_mm = 0.2f;
  p.missing_min = p.missing_max = 0.0f;
  p.total_features = 0;
  GenerateSyntheticScene(models_, p, 5, synthetic_.get());
  Scene& scene = synthetic_->scene;
  // A second copy of the object shifted by 80 mm, every feature sharing its left source with
  // the original: stereo ambiguity, not a second object.
  const size_t np = scene.points.size(), nl = scene.lines.size();
  for (size_t i = 0; i < np; ++i) {
    ScenePoint q = scene.points[i];
    q.p_mm += Eigen::Vector3f(80, 0, 0);
    q.source.right = uint16_t(1000 + i);
    ASSERT_TRUE(scene.points.push_back(q));
  }
  for (size_t i = 0; i < nl; ++i) {
    SceneLine l = scene.lines[i];
    l.a_mm += Eigen::Vector3f(80, 0, 0);
    l.b_mm += Eigen::Vector3f(80, 0, 0);
    l.source.right = uint16_t(1000 + i);
    ASSERT_TRUE(scene.lines.push_back(l));
  }
  SceneSupportVerifier verifier;
  ASSERT_TRUE(recognizer->Recognize(scene, verifier, Budget{}, objects_).ok());
  EXPECT_EQ(objects_.size(), 1u);
}

}  // namespace
}  // namespace sh
