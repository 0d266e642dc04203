#include "recog/base/init_block.hpp"

#include <gtest/gtest.h>

#include <cstdint>

namespace sh {
namespace {

TEST(InitBlock, PiecesAreAlignedZeroedAndWithinTheBlock) {
  InitBlock block;
  const size_t bytes = InitBlock::PieceBytes<uint8_t>(3) + InitBlock::PieceBytes<float>(100) +
                       InitBlock::PieceBytes<uint32_t>(7);
  ASSERT_TRUE(block.Allocate(bytes));
  EXPECT_EQ(block.bytes(), bytes);
  uint8_t* a = block.Take<uint8_t>(3);
  float* b = block.Take<float>(100);
  uint32_t* c = block.Take<uint32_t>(7);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  ASSERT_NE(c, nullptr);
  for (const void* p :
       {static_cast<const void*>(a), static_cast<const void*>(b), static_cast<const void*>(c)}) {
    EXPECT_EQ(reinterpret_cast<uintptr_t>(p) % InitBlock::kAlign, 0u);
  }
  // Pieces do not overlap and are zero.
  EXPECT_GE(reinterpret_cast<uintptr_t>(b), reinterpret_cast<uintptr_t>(a + 3));
  EXPECT_GE(reinterpret_cast<uintptr_t>(c), reinterpret_cast<uintptr_t>(b + 100));
  for (int i = 0; i < 100; ++i) EXPECT_EQ(b[i], 0.0f);
}

TEST(InitBlock, TooSmallABlockGivesNull) {
  InitBlock block;
  EXPECT_EQ(block.Take<uint8_t>(1), nullptr);  // nothing allocated
  ASSERT_TRUE(block.Allocate(InitBlock::PieceBytes<uint32_t>(10)));
  EXPECT_EQ(block.Take<uint32_t>(11 + InitBlock::kAlign), nullptr);
  EXPECT_NE(block.Take<uint32_t>(10), nullptr);
  EXPECT_EQ(block.Take<uint32_t>(InitBlock::kAlign), nullptr);
  // A new allocation starts over.
  ASSERT_TRUE(block.Allocate(InitBlock::PieceBytes<uint32_t>(10)));
  EXPECT_NE(block.Take<uint32_t>(10), nullptr);
}

}  // namespace
}  // namespace sh
