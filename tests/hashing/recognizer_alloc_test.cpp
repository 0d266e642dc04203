// Proves that recognition does not touch the heap after initialisation: every operator new in
// this binary is counted, and the count must not change across Recognize() calls.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "tests/support/counting_allocator.hpp"
#include "tests/support/tables_fixture.hpp"

namespace sh {
namespace {

TEST(RecognizerAllocations, NoneAfterInitialisation) {
  auto view = OpenDefaultTable();
  ASSERT_TRUE(view.ok());
  const std::vector<Model> models = testing::ModelsOf(*view);
  auto recognizer = testing::MakeRecognizer(*view);
  std::vector<std::unique_ptr<SyntheticScene>> scenes;
  SyntheticSceneParams p;
  p.total_features = 1000;
  for (int i = 0; i < 10; ++i) {
    scenes.push_back(std::make_unique<SyntheticScene>());
    GenerateSyntheticScene(models, p, 40 + i, scenes.back().get());
  }
  static Vector<RecognizedObject, kMaxObjects> objects;
  SceneSupportVerifier verifier;
  RecognitionStats stats;
  size_t found = 0;
  const uint64_t before = testing::HeapAllocations();
  for (const auto& s : scenes) {
    ASSERT_TRUE(recognizer->Recognize(s->scene, verifier, Budget{}, objects, &stats).ok());
    found += objects.size();
  }
  const uint64_t after = testing::HeapAllocations();
  EXPECT_EQ(after - before, 0u) << "heap allocations during recognition";
  EXPECT_GT(found, 0u);  // the scenes were actually recognised, not skipped
  // The counter works: an allocation here is seen.
  const uint64_t probe_before = testing::HeapAllocations();
  auto* probe = new int(1);
  const uint64_t probe_after = testing::HeapAllocations();
  delete probe;
  EXPECT_EQ(probe_after, probe_before + 1);
}

}  // namespace
}  // namespace sh
