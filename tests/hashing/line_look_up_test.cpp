#include "recog/hashing/line_look_up.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <memory>
#include <random>

#include "recog/hashing/basis.hpp"
#include "recog/hashing/pose_refine.hpp"
#include "recog/hashing/vote_lut.hpp"
#include "tables/table_file.hpp"
#include "tests/support/random_geometry.hpp"

namespace sh {
namespace {

constexpr float kSigmaMm = 2.0f;  // the default vote width of lines
constexpr float kInvSigma2 = 1.0f / (kSigmaMm * kSigmaMm);

using testing::RandomUnit;

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

// Four entries at once: each test still rules out its own case in its own lane, and on the
// built-in table every entry that votes is kept, while most are not.
TEST(LineLookUp, KeptLanesAreTheEntriesThatMayVote) {
  const Eigen::Vector3f v = Eigen::Vector3f(1.0f, 0.2f, -0.1f).normalized();
  const LineLookUp q =
      LineLookUp::For(SupportVector(Eigen::Vector3f(10, 20, 30), v), v, kInvSigma2);
  const Eigen::Vector3f on_line = q.s + 15.0f * v;
  const Eigen::Vector3f turned = (Eigen::AngleAxisf(0.5236f, q.n) * v).normalized();
  const Eigen::Vector3f centres[4] = {on_line + 0.5f * q.n, on_line + 6.0f * q.n,
                                      on_line + 6.0f * q.m, on_line};
  const Eigen::Vector3f directions[4] = {v, v, v, turned};
  LineDirectionIndex::Lanes lanes{};
  for (int k = 0; k < 4; ++k) {
    lanes.cx[k] = centres[k].x();
    lanes.cy[k] = centres[k].y();
    lanes.cz[k] = centres[k].z();
    lanes.ux[k] = directions[k].x();
    lanes.uy[k] = directions[k].y();
    lanes.uz[k] = directions[k].z();
    lanes.length_mm[k] = k == 3 ? 40.0f : 30.0f;
  }
  EXPECT_EQ(q.KeptLanes(lanes), 1u);
  lanes.length_mm[3] = 10.0f;  // short enough to vote though turned
  EXPECT_EQ(q.KeptLanes(lanes), 9u);

  auto view = OpenDefaultTable();
  ASSERT_TRUE(view.ok());
  auto index = std::make_unique<LineDirectionIndex>();
  ASSERT_TRUE(index->Build(*view, 12.0f * float(kVoteCutoff) / kInvSigma2));
  const uint32_t n = view->line_entry_count();
  const VoteTable lut;
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> offset_mm(-4.0f, 4.0f);
  int kept = 0, visited = 0, voted = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const LineDirectionIndex::Entry e = index->entry(rng() % n);
    const Eigen::Vector3f u =
        (Eigen::Vector3f(e.ux, e.uy, e.uz) + 0.05f * RandomUnit(rng)).normalized();
    const Eigen::Vector3f through = Eigen::Vector3f(e.cx, e.cy, e.cz) +
                                    Eigen::Vector3f(offset_mm(rng), offset_mm(rng), offset_mm(rng));
    const LineLookUp look = LineLookUp::For(SupportVector(through, u), u, kInvSigma2);
    for (uint32_t i = 0; i < n; i += 4) {
      const unsigned bits = look.KeptLanes(index->LanesAt(i));
      for (uint32_t k = 0; k < 4 && i + k < n; ++k) {
        const bool lane_kept = (bits >> k) & 1u;
        const uint16_t vote = VoteOf(lut, look, index->entry(i + k));
        ASSERT_TRUE(vote == 0 || lane_kept) << "entry " << i + k << " in trial " << trial;
        kept += lane_kept;
        voted += vote > 0;
        ++visited;
      }
    }
  }
  EXPECT_GT(voted, 0);
  EXPECT_LT(kept, visited / 10);
}

}  // namespace
}  // namespace sh
