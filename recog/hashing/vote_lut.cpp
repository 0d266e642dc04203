#include "recog/hashing/vote_lut.hpp"

#include <cmath>

namespace sh {

VoteTable::VoteTable() {
  for (int i = 0; i <= kVoteTableSize; ++i) {
    const double x = double(i) / double(1 << kVoteIndexFractionBits);  // UQ8.8 -> value
    // exp(-x) in [0, 1] -> UQ0.16 raw, saturating 1.0 to 0xffff.
    table_[i] = UQVote::FromDouble(std::exp(-x)).raw();
  }
}

}  // namespace sh
