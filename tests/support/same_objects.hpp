// Two searches' objects compared exactly: what a thread count must not change.
#pragma once

#include <gtest/gtest.h>

#include "recog/hashing/recognizer.hpp"

namespace sh::testing {

// The same objects in the same order: models, poses, votes and verifier evidence, bit for bit.
inline void ExpectSameObjects(const Vector<RecognizedObject>& a, const Vector<RecognizedObject>& b,
                              uint64_t seed) {
  ASSERT_EQ(a.size(), b.size()) << "seed " << seed;
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].model, b[i].model) << "seed " << seed;
    EXPECT_EQ(a[i].cam_T_model.t_mm, b[i].cam_T_model.t_mm) << "seed " << seed;
    EXPECT_EQ(a[i].cam_T_model.R, b[i].cam_T_model.R) << "seed " << seed;
    EXPECT_EQ(a[i].vote, b[i].vote) << "seed " << seed;
    EXPECT_EQ(a[i].verify_evidence, b[i].verify_evidence) << "seed " << seed;
  }
}

}  // namespace sh::testing
