// Proves that recognition does not touch the heap after initialisation: every operator new in
// this binary is counted, and the count must not change across Recognize() calls.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "tests/hashing/fixtures.hpp"

namespace {
std::atomic<long> g_allocations{0};
}

void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace sh {
namespace {

TEST(RecognizerAllocations, NoneAfterInitialisation) {
  auto view = OpenDefaultTable();
  ASSERT_TRUE(view.ok());
  const std::vector<Model> models = testing_support::ModelsOf(*view);
  auto recognizer = testing_support::MakeRecognizer(*view);
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
  const long before = g_allocations.load();
  for (const auto& s : scenes) {
    ASSERT_TRUE(recognizer->Recognize(s->scene, verifier, Budget{}, objects, &stats).ok());
    found += objects.size();
  }
  const long after = g_allocations.load();
  EXPECT_EQ(after - before, 0) << "heap allocations during recognition";
  EXPECT_GT(found, 0u);  // the scenes were actually recognised, not skipped
  // The counter works: an allocation here is seen.
  const long probe_before = g_allocations.load();
  auto* probe = new int(1);
  const long probe_after = g_allocations.load();
  delete probe;
  EXPECT_EQ(probe_after, probe_before + 1);
}

}  // namespace
}  // namespace sh
