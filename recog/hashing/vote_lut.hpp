// The Gaussian vote exp(-d^2 / sigma^2) through a fixed-point lookup table.
//
// exp() per match cost a quarter of the recognition time in the thesis. The table is indexed by
// x = d^2 / sigma^2 in UQ8.8 (256 steps per unit) over [0, kVoteCutoff) and holds votes in
// UQ0.16; between two table entries the vote is interpolated linearly in integer arithmetic.
// Matches with x >= kVoteCutoff (d >= 2 sigma) vote 0: exp(-4) = 1.8 % is below what matters
// and the cut bounds the neighbourhood that look-ups must visit.
#pragma once

#include <cstdint>

#include "recog/base/fixed_point.hpp"

namespace sh {

inline constexpr int kVoteCutoff = 4;                                         // in units of sigma^2
inline constexpr int kVoteIndexFractionBits = 8;                              // x is UQ8.8
inline constexpr int kVoteTableSize = kVoteCutoff << kVoteIndexFractionBits;  // 1024 entries

using QVoteIndex = UQ<8, kVoteIndexFractionBits>;  // x = d^2 / sigma^2

class VoteTable {
 public:
  VoteTable();  // fills the table once; constexpr-free so that it works with any libm

  // Vote for x = d^2/sigma^2 given in UQ8.16 raw units (UQ8.8 table index plus
  // kInterpolationBits bits to interpolate with); result in UQ0.16 raw units.
  uint16_t VoteRaw(uint32_t x_raw) const {
    if (x_raw >= uint32_t(kVoteTableSize) << kInterpolationBits) return 0;
    // x_raw carries kInterpolationBits more fraction bits than the table index.
    const uint32_t i = x_raw >> kInterpolationBits;
    const uint32_t frac = x_raw & ((1u << kInterpolationBits) - 1);
    const uint32_t a = table_[i], b = table_[i + 1];
    // a + (b - a) * frac / 2^k, with b <= a (the Gaussian decreases).
    return static_cast<uint16_t>(a - (((a - b) * frac) >> kInterpolationBits));
  }

  // Convenience: d^2 and 1/sigma^2 in float -> UQ0.16 raw vote.
  uint16_t Vote(float d2_mm2, float inv_sigma2) const {
    const float x = d2_mm2 * inv_sigma2;
    if (!(x < float(kVoteCutoff))) return 0;
    // A rounding error below zero is a distance of zero (converting a negative float to an
    // unsigned integer is undefined, and x86 and ARM do differ on it).
    if (!(x > 0.0f)) return VoteRaw(0);
    // x -> fine index: x * 2^(8 + k), truncated (the interpolation absorbs the truncation).
    return VoteRaw(
        static_cast<uint32_t>(x * float(1u << (kVoteIndexFractionBits + kInterpolationBits))));
  }

  static constexpr int kInterpolationBits = 8;  // extra fraction bits used to interpolate

 private:
  uint16_t table_[kVoteTableSize + 1];
};

}  // namespace sh
