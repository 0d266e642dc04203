#include "recog/base/zeroed.hpp"

#include <gtest/gtest.h>

#include <cstdint>

namespace sh {
namespace {

// A large object like the pipeline's: arrays without initialisers beside members with them.
struct Buffers {  // NOLINT(cppcoreguidelines-pro-type-member-init): zero from MakeZeroed
  int32_t counter = 7;
  uint8_t pixels[3 << 20];
  float plane[1 << 16];
  bool ready = true;
};

int g_destroyed = 0;
struct Counted {  // NOLINT(cppcoreguidelines-pro-type-member-init)
  uint32_t words[1 << 12];
  ~Counted() { ++g_destroyed; }
};

TEST(Zeroed, ReadsAsValueInitialisedWithMemberInitialisersApplied) {
  // Dirty the heap first so that reused memory would show through.
  for (int i = 0; i < 4; ++i) {
    auto dirty = std::make_unique<uint8_t[]>(sizeof(Buffers));
    for (size_t b = 0; b < sizeof(Buffers); b += 512) dirty[b] = 0xA5;
  }
  ZeroedPtr<Buffers> buffers = MakeZeroed<Buffers>();
  ASSERT_NE(buffers, nullptr);
  EXPECT_EQ(buffers->counter, 7);
  EXPECT_TRUE(buffers->ready);
  size_t nonzero = 0;
  for (uint8_t p : buffers->pixels) nonzero += p != 0;
  for (float f : buffers->plane) nonzero += f != 0.0f;
  EXPECT_EQ(nonzero, 0u);
}

TEST(Zeroed, SmallObjectsFromReusedMemoryAreZeroToo) {
  for (int i = 0; i < 8; ++i) {
    auto dirty = std::make_unique<uint32_t[]>(1 << 12);
    for (size_t w = 0; w < (1u << 12); ++w) dirty[w] = 0xDEADBEEFu;
  }
  ZeroedPtr<Counted> counted = MakeZeroed<Counted>();
  ASSERT_NE(counted, nullptr);
  size_t nonzero = 0;
  for (uint32_t w : counted->words) nonzero += w != 0;
  EXPECT_EQ(nonzero, 0u);
}

TEST(Zeroed, TheDeleterRunsTheDestructor) {
  g_destroyed = 0;
  { ZeroedPtr<Counted> counted = MakeZeroed<Counted>(); }
  EXPECT_EQ(g_destroyed, 1);
}

}  // namespace
}  // namespace sh
