// The search on several threads (Recognizer::SetParallel) against the search on one: the
// hypotheses of a scene basis are refined and verified together when the verifier allows it,
// then taken in order, so the search sees the same outcomes and finds the same objects.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <cstring>
#include <memory>
#include <thread>
#include <vector>

#include "recog/hashing/recognizer.hpp"
#include "tests/support/same_objects.hpp"
#include "tests/support/tables_fixture.hpp"

namespace sh {
namespace {

using testing::ExpectSameObjects;
using testing::MakeRecognizer;
using testing::ModelsOf;

// A ParallelFor on `*threads` threads started for each call (the pipeline's pool keeps its
// threads; here only the spreading matters): thread t runs indices t, t + threads, ... so that
// index 1 always runs off the calling thread.
ParallelFor OnThreads(int* threads) {
  ParallelFor parallel;
  parallel.pool = threads;
  parallel.run = [](void* pool, int n, void (*fn)(void*, int), void* context) {
    const int stride = *static_cast<int*>(pool);
    auto work = [=](int first) {
      for (int i = first; i < n; i += stride) fn(context, i);
    };
    std::vector<std::thread> others;
    for (int t = 1; t < stride; ++t) others.emplace_back(work, t);
    work(0);
    for (std::thread& t : others) t.join();
  };
  return parallel;
}

// SceneSupportVerifier's verdicts, counting the calls made off the thread that built it.
class ThreadCountingVerifier : public HypothesisVerifier {
 public:
  explicit ThreadCountingVerifier(bool concurrent) : concurrent_(concurrent) {}
  bool Verify(const Model& model, const Vector<RecognizedObject>& accepted,
              RecognizedObject& candidate) override {
    if (std::this_thread::get_id() != caller_) ++off_caller;
    return inner_.Verify(model, accepted, candidate);
  }
  bool ConcurrentVerify() const override { return concurrent_; }
  std::atomic<int> off_caller{0};

 private:
  bool concurrent_;
  std::thread::id caller_ = std::this_thread::get_id();
  SceneSupportVerifier inner_;
};

// Every hypothesis the search reports, in order, with its outcome and refined pose.
class OutcomeLog : public SearchObserver {
 public:
  struct Entry {
    uint32_t basis_number;
    uint32_t model_basis;
    Outcome outcome;
    Eigen::Vector3f t_mm;
    float evidence;
    bool operator==(const Entry& o) const {
      return basis_number == o.basis_number && model_basis == o.model_basis &&
             outcome == o.outcome && t_mm == o.t_mm && evidence == o.evidence;
    }
  };
  void OnHypothesis(uint32_t basis_number, const Hypothesis& h, const RecognizedObject& candidate,
                    Outcome outcome) override {
    entries.push_back({basis_number, h.model_basis, outcome, candidate.cam_T_model.t_mm,
                       candidate.verify_evidence});
  }
  void OnAccepted(uint32_t, const RecognizedObject&) override {}
  std::vector<Entry> entries;
};

struct SearchRun {
  OutcomeLog log;
  RecognitionStats stats;
  Vector<RecognizedObject, kMaxObjects> objects;
  int off_caller = 0;
};

void Search(Recognizer& recognizer, const Scene& scene, bool concurrent, SearchRun* run) {
  ThreadCountingVerifier verifier(concurrent);
  recognizer.SetObserver(&run->log);
  const Status s = recognizer.Recognize(scene, verifier, Budget{}, run->objects, &run->stats);
  recognizer.SetObserver(nullptr);
  ASSERT_TRUE(s.ok()) << s.message();
  run->off_caller = verifier.off_caller;
}

void ExpectSame(const SearchRun& a, const SearchRun& b, uint64_t seed) {
  EXPECT_TRUE(a.log.entries == b.log.entries) << "seed " << seed;
  EXPECT_EQ(a.stats.scene_bases_tried, b.stats.scene_bases_tried) << "seed " << seed;
  EXPECT_EQ(a.stats.hypotheses, b.stats.hypotheses) << "seed " << seed;
  EXPECT_EQ(a.stats.verifications, b.stats.verifications) << "seed " << seed;
  EXPECT_EQ(a.stats.deferred, b.stats.deferred) << "seed " << seed;
  EXPECT_EQ(a.stats.deferred_accepted, b.stats.deferred_accepted) << "seed " << seed;
  ExpectSameObjects(a.objects, b.objects, seed);
}

TEST(RecognizerThreads, VerifiesTheHypothesesOfABasisTogetherAndFindsWhatOneThreadFinds) {
  auto view = OpenDefaultTable();
  ASSERT_TRUE(view.ok());
  const std::vector<Model> models = ModelsOf(*view);
  RecognizerConfig config;
  config.hypotheses_per_basis = 6;  // as the pipeline: several hypotheses to spread
  config.compete_bases = 5;
  // Challengers voted afresh at a lower threshold, as in the automatic preset.
  config.compete_vote_factor = 0.6f;
  config.compete_extra_matches = 0;
  config.defer_below_score = 0.5f;  // weakly confirmed objects wait, as in the pipeline
  auto one = MakeRecognizer(*view, config);
  auto two = MakeRecognizer(*view, config);
  int threads = 2;
  ASSERT_TRUE(two->SetParallel(OnThreads(&threads), threads).ok());
  auto synthetic = std::make_unique<SyntheticScene>();
  SyntheticSceneParams p;
  p.total_features = 400;
  int compared = 0, off_caller = 0;
  uint32_t held_back = 0;
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    GenerateSyntheticScene(models, p, seed, synthetic.get());
    SearchRun alone, spread, serial;
    Search(*one, synthetic->scene, true, &alone);
    Search(*two, synthetic->scene, true, &spread);
    // A verifier that does not allow it is called on the calling thread alone.
    Search(*two, synthetic->scene, false, &serial);
    EXPECT_EQ(alone.off_caller, 0);
    EXPECT_EQ(serial.off_caller, 0);
    ExpectSame(alone, spread, seed);
    ExpectSame(alone, serial, seed);
    compared += int(alone.objects.size());
    off_caller += spread.off_caller;
    held_back += alone.stats.deferred;
  }
  EXPECT_GT(compared, 6);    // the scenes held objects to compare
  EXPECT_GT(held_back, 0u);  // and weakly confirmed ones that waited
  EXPECT_GT(off_caller, 0);  // and the other thread verified some of the hypotheses
}

// The second thread's vote arrays lent while the recogniser is idle (the rescue's counters in the
// pipeline): what the borrower wrote is cleared before the next search, which then finds what one
// thread finds; lent twice, the larger loan is cleared. More than the arrays hold is refused.
TEST(RecognizerThreads, LentVoteScratchIsClearedBeforeTheNextSearch) {
  auto view = OpenDefaultTable();
  ASSERT_TRUE(view.ok());
  const std::vector<Model> models = ModelsOf(*view);
  RecognizerConfig config;
  config.hypotheses_per_basis = 6;
  auto one = MakeRecognizer(*view, config);
  auto two = MakeRecognizer(*view, config);
  EXPECT_EQ(two->LendVoteScratch(64).bytes, nullptr);  // one thread: no second arrays
  int threads = 2;
  ASSERT_TRUE(two->SetParallel(OnThreads(&threads), threads).ok());
  EXPECT_EQ(two->LendVoteScratch(SIZE_MAX).bytes, nullptr);
  auto synthetic = std::make_unique<SyntheticScene>();
  SyntheticSceneParams p;
  p.total_features = 400;
  int compared = 0;
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    GenerateSyntheticScene(models, p, seed, synthetic.get());
    const Recognizer::LentMemory big = two->LendVoteScratch(size_t{256} << 10);
    const Recognizer::LentMemory small = two->LendVoteScratch(size_t{16} << 10);
    ASSERT_NE(big.bytes, nullptr);
    ASSERT_EQ(small.bytes, big.bytes);
    EXPECT_EQ(small.size, size_t{16} << 10);
    std::memset(big.bytes, 0x5A, big.size);
    SearchRun alone, spread;
    Search(*one, synthetic->scene, true, &alone);
    Search(*two, synthetic->scene, true, &spread);
    ExpectSame(alone, spread, seed);
    compared += int(alone.objects.size());
  }
  EXPECT_GT(compared, 3);
}

}  // namespace
}  // namespace sh
