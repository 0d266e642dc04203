// Recognition speed on synthetic 3-D scenes: one scene basis, and whole scenes of 100 to 2,000
// features with up to five objects (hash fn 5, the default tables). Single thread.
//   build/<dir>/tests/hashing/recognizer_bench
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <memory>

#include "tables/table_file.hpp"
#include "tests/support/tables_fixture.hpp"

namespace sh {
namespace {

struct Fixture {
  TableView view;
  std::vector<Model> models;
  std::unique_ptr<Recognizer> recognizer;
  Fixture() {
    view = *OpenDefaultTable();
    models = testing::ModelsOf(view);
    recognizer = std::make_unique<Recognizer>();
    (void)recognizer->Init(view, RecognizerConfig{});
  }
};

Fixture& Shared() {
  static Fixture f;
  return f;
}

void SetMemoryCounters(benchmark::State& state) {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  state.counters["peak_rss_MiB"] = double(usage.ru_maxrss) / 1024.0;
  state.counters["blob_KiB"] = double(DefaultTableBlobSize()) / 1024.0;
}

// Voting for one scene basis in a 1,000-feature scene (the inner loop of recognition).
void BM_VoteOneSceneBasis(benchmark::State& state) {
  Fixture& f = Shared();
  auto scene = std::make_unique<SyntheticScene>();
  SyntheticSceneParams p;
  p.min_objects = p.max_objects = 5;
  p.total_features = 1000;
  GenerateSyntheticScene(f.models, p, 1, scene.get());
  f.recognizer->PrepareScene(scene->scene);
  Vector<Hypothesis, kMaxHypothesesPerBasis> hypotheses;
  uint32_t i = 0;
  const uint32_t n = std::min<uint32_t>(f.recognizer->CandidateCount(), 256);
  for (auto _ : state) {
    benchmark::DoNotOptimize(f.recognizer->VoteForBasis(f.recognizer->Candidate(i), hypotheses));
    i = (i + 1) % n;
  }
  SetMemoryCounters(state);
}
BENCHMARK(BM_VoteOneSceneBasis)->Unit(benchmark::kMicrosecond);

// Whole scenes: five objects (or 1-5 when range(1) == 0) among range(0) features.
void BM_RecogniseScene(benchmark::State& state) {
  Fixture& f = Shared();
  constexpr int kScenes = 16;
  std::vector<std::unique_ptr<SyntheticScene>> scenes;
  SyntheticSceneParams p;
  p.total_features = int(state.range(0));
  if (state.range(1) != 0) p.min_objects = p.max_objects = int(state.range(1));
  for (int i = 0; i < kScenes; ++i) {
    scenes.push_back(std::make_unique<SyntheticScene>());
    GenerateSyntheticScene(f.models, p, 1000 + i, scenes.back().get());
  }
  static Vector<RecognizedObject, kMaxObjects> objects;
  SceneSupportVerifier verifier;
  int i = 0;
  size_t found = 0, truth = 0;
  for (auto _ : state) {
    (void)f.recognizer->Recognize(scenes[i]->scene, verifier, Budget{}, objects);
    found += objects.size();
    truth += scenes[i]->truth.size();
    i = (i + 1) % kScenes;
  }
  state.counters["objects_found_per_truth"] = truth ? double(found) / double(truth) : 0.0;
  state.SetComplexityN(state.range(0));
  SetMemoryCounters(state);
}
BENCHMARK(BM_RecogniseScene)
    ->ArgsProduct({{100, 250, 500, 1000, 2000}, {5}})
    ->Unit(benchmark::kMillisecond)
    ->Complexity();

}  // namespace
}  // namespace sh

BENCHMARK_MAIN();
