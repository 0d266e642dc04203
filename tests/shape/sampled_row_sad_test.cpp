// One row of blob matching in byte vectors: the same sums as a plain loop over every other
// pixel, for runs of every length around the vector blocks, at every alignment, with colours
// spanning the whole byte range (differences of 255 in every channel included).
#include "recog/shape/sampled_row_sad.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <random>
#include <vector>

namespace sh {
namespace {

constexpr uint8_t kColour = 4;

// The reference, byte by byte: pixel x occupies bytes 3 x .. 3 x + 2, and the even pixels
// from 0 to 2 (n - 1) count.
SampledRowSad PlainSad(const Rgb8* src, const Rgb8* dst, const uint8_t* classes, int n) {
  const auto* s = reinterpret_cast<const uint8_t*>(src);
  const auto* d = reinterpret_cast<const uint8_t*>(dst);
  SampledRowSad out;
  for (ptrdiff_t x = 0; x <= 2 * (static_cast<ptrdiff_t>(n) - 1); x += 2) {
    if (classes[x] == kColour) ++out.same;
    for (ptrdiff_t byte = 3 * x; byte < 3 * x + 3; ++byte) {
      out.sad += static_cast<uint32_t>(s[byte] > d[byte] ? s[byte] - d[byte] : d[byte] - s[byte]);
    }
  }
  return out;
}

struct Rows {
  static constexpr int kWidth = 1280;  // the widest image
  std::vector<Rgb8> src = std::vector<Rgb8>(kWidth), dst = std::vector<Rgb8>(kWidth);
  std::vector<uint8_t> classes = std::vector<uint8_t>(kWidth);

  explicit Rows(unsigned seed, bool extremes) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> byte(0, 255), bit(0, 1), cls(0, 7);
    const auto value = [&] { return static_cast<uint8_t>(extremes ? 255 * bit(rng) : byte(rng)); };
    for (int x = 0; x < kWidth; ++x) {
      src[x] = {value(), value(), value()};
      dst[x] = {value(), value(), value()};
      classes[x] = static_cast<uint8_t>(cls(rng) < 3 ? kColour : cls(rng));
    }
  }
};

TEST(SampledRowSad, EqualsPlainLoopForEveryLengthAndAlignment) {
  for (unsigned seed = 0; seed < 4; ++seed) {
    const Rows rows(seed, seed % 2 == 1);
    for (int start = 0; start < 20; ++start) {
      for (int n = 0; 2 * (n - 1) + start < Rows::kWidth; n += n < 40 ? 1 : 37) {
        const SampledRowSad fast = SampleRowSad(rows.src.data() + start, rows.dst.data() + start,
                                                rows.classes.data() + start, n, kColour);
        const SampledRowSad plain = PlainSad(rows.src.data() + start, rows.dst.data() + start,
                                             rows.classes.data() + start, n);
        ASSERT_EQ(fast.sad, plain.sad) << "seed " << seed << " start " << start << " n " << n;
        ASSERT_EQ(fast.same, plain.same) << "seed " << seed << " start " << start << " n " << n;
      }
    }
  }
}

TEST(SampledRowSad, WidestRowOfLargestDifferencesDoesNotOverflow) {
  // Every sampled channel differs by 255 and every class matches, across a whole image row.
  std::vector<Rgb8> white(Rows::kWidth, Rgb8{255, 255, 255}), black(Rows::kWidth);
  std::vector<uint8_t> classes(Rows::kWidth, kColour);
  const int n = Rows::kWidth / 2;
  const SampledRowSad r = SampleRowSad(white.data(), black.data(), classes.data(), n, kColour);
  EXPECT_EQ(r.sad, 3u * 255u * static_cast<uint32_t>(n));
  EXPECT_EQ(r.same, static_cast<uint32_t>(n));
}

}  // namespace
}  // namespace sh
