#include "recog/hashing/vote_lut.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace sh {
namespace {

// The fixed-point vote against exp(-x) in double over the whole input range, every raw input.
TEST(VoteTable, MatchesTheDoubleReferenceEverywhere) {
  const VoteTable table;
  const uint32_t fraction_bits = kVoteIndexFractionBits + VoteTable::kInterpolationBits;
  const uint32_t end = uint32_t(kVoteCutoff) << fraction_bits;
  double max_error = 0.0;
  for (uint32_t raw = 0; raw < end; ++raw) {
    const double x = double(raw) / double(1u << fraction_bits);
    const double vote = double(table.VoteRaw(raw)) / 65536.0;
    max_error = std::max(max_error, std::fabs(vote - std::exp(-x)));
  }
  RecordProperty("max_abs_error", std::to_string(max_error));
  std::printf("fixed-point vote: max |error| = %.3g over x in [0, %d)\n", max_error, kVoteCutoff);
  // Linear interpolation over steps of 1/256 errs by at most h^2/8 = 1.9e-6, rounding to UQ0.16
  // adds 2^-17 = 7.6e-6 and the saturated 1.0 (0xffff) 2^-16 = 1.5e-5: 2.5e-5 in all.
  EXPECT_LT(max_error, 2.5e-5);
  EXPECT_EQ(table.VoteRaw(end), 0);
  EXPECT_EQ(table.Vote(1e9f, 1.0f), 0);
  EXPECT_EQ(table.Vote(std::nanf(""), 1.0f), 0);
  // A distance rounded below zero is a distance of zero: the full vote, on every processor.
  EXPECT_EQ(table.Vote(-1e-3f, 1.0f), table.VoteRaw(0));
  EXPECT_EQ(table.Vote(-2.0f, 1.0f), table.VoteRaw(0));
}

TEST(VoteTable, DecreasesWithDistance) {
  const VoteTable table;
  uint16_t previous = 0xffff;
  for (float d2 = 0.0f; d2 < 36.0f; d2 += 0.05f) {
    const uint16_t v = table.Vote(d2, 1.0f / 9.0f);
    EXPECT_LE(v, previous);
    previous = v;
  }
}

}  // namespace
}  // namespace sh
