#include "recog/hashing/line_look_up.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "recog/hashing/basis.hpp"
#include "recog/hashing/pose_refine.hpp"
#include "recog/hashing/vote_lut.hpp"
#include "tables/table_file.hpp"

namespace sh {
namespace {

constexpr float kSigmaMm = 2.0f;  // the default vote width of lines
constexpr float kInvSigma2 = 1.0f / (kSigmaMm * kSigmaMm);

Eigen::Vector3f RandomUnit(std::mt19937& rng) {
  std::normal_distribution<float> n(0.0f, 1.0f);
  return Eigen::Vector3f(n(rng), n(rng), n(rng)).normalized();
}

uint16_t VoteOf(const VoteTable& lut, const LineLookUp& q, const LineDirectionIndex::Entry& l) {
  return lut.Vote(
      SegmentLineDistance2({l.cx, l.cy, l.cz}, {l.ux, l.uy, l.uz}, l.length_mm, q.s, q.v),
      kInvSigma2);
}

// The tests only save work: no entry of the built-in table that they rule out would have voted,
// for scene lines near and along its own entries (where votes happen) and random ones.
TEST(LineLookUp, RulesOutOnlyEntriesThatCannotVote) {
  auto view = OpenDefaultTable();
  ASSERT_TRUE(view.ok());
  const uint32_t n = view->line_entry_count();
  const VoteTable lut;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> offset_mm(-4.0f, 4.0f);
  int ruled_out = 0, voted = 0;
  for (int trial = 0; trial < 400; ++trial) {
    // A line through an entry's centre, a few mm off and a few degrees turned.
    const LineDirectionIndex::Entry e = DecodeLineEntry(view->line_entries()[rng() % n], 0);
    Eigen::Vector3f v = (Eigen::Vector3f(e.ux, e.uy, e.uz) + 0.05f * RandomUnit(rng)).normalized();
    if (trial % 4 == 3) v = RandomUnit(rng);
    const Eigen::Vector3f through = Eigen::Vector3f(e.cx, e.cy, e.cz) +
                                    Eigen::Vector3f(offset_mm(rng), offset_mm(rng), offset_mm(rng));
    const LineLookUp q = LineLookUp::For(SupportVector(through, v), v, kInvSigma2);
    for (uint32_t i = 0; i < n; ++i) {
      const LineDirectionIndex::Entry l = DecodeLineEntry(view->line_entries()[i], i);
      const uint16_t vote = VoteOf(lut, q, l);
      if (q.RulesOut(l)) {
        ++ruled_out;
        ASSERT_EQ(vote, 0) << "entry " << i << " ruled out in trial " << trial;
      }
      voted += vote > 0;
    }
  }
  EXPECT_GT(ruled_out, 0);
  EXPECT_GT(voted, 0);
}

// Each test on its own: a centre off the line along n, one off along m (the n offset zero),
// and a long segment turned away, are ruled out; a nearby parallel segment is not.
TEST(LineLookUp, EachTestRulesOutItsOwnCase) {
  const Eigen::Vector3f v = Eigen::Vector3f(1.0f, 0.2f, -0.1f).normalized();
  const Eigen::Vector3f s = SupportVector(Eigen::Vector3f(10.0f, 20.0f, 30.0f), v);
  const LineLookUp q = LineLookUp::For(s, v, kInvSigma2);
  EXPECT_NEAR(q.n.dot(v), 0.0f, 1e-6f);
  EXPECT_NEAR(q.m.dot(v), 0.0f, 1e-6f);
  EXPECT_NEAR(q.n.dot(q.m), 0.0f, 1e-6f);
  auto entry = [](const Eigen::Vector3f& centre, const Eigen::Vector3f& u, float length) {
    LineDirectionIndex::Entry l{};
    l.cx = centre.x();
    l.cy = centre.y();
    l.cz = centre.z();
    l.ux = u.x();
    l.uy = u.y();
    l.uz = u.z();
    l.length_mm = length;
    return l;
  };
  const Eigen::Vector3f on_line = s + 15.0f * v;
  const float far_mm = 3.0f * kSigmaMm;  // beyond the 2 sigma cut
  EXPECT_FALSE(q.RulesOut(entry(on_line + 0.5f * q.n, v, 30.0f)));
  EXPECT_TRUE(q.RulesOut(entry(on_line + far_mm * q.n, v, 30.0f)));
  EXPECT_TRUE(q.RulesOut(entry(on_line + far_mm * q.m, v, 30.0f)));
  // Both offsets under the cut alone, together over it.
  const float part_mm = 0.8f * 2.0f * kSigmaMm;
  EXPECT_TRUE(q.RulesOut(entry(on_line + part_mm * q.n + part_mm * q.m, v, 30.0f)));
  // 30 degrees off at 40 mm: L^2/12 sin^2 = 33 mm^2, over 4 sigma^2 = 16 mm^2.
  const Eigen::Vector3f turned = (Eigen::AngleAxisf(0.5236f, q.n) * v).normalized();
  EXPECT_TRUE(q.RulesOut(entry(on_line, turned, 40.0f)));
  EXPECT_FALSE(q.RulesOut(entry(on_line, turned, 10.0f)));
}

}  // namespace
}  // namespace sh
