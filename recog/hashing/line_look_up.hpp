// A scene line's look-up in the hash table's line entries: the line in the basis frame and the
// tests that rule an entry out before its vote is computed.
//
// The vote of a model segment (centre c, unit direction u, length L) for the scene line
// (support vector s, unit direction v) is the Gaussian of eq. 4.4, d^2 = |perpendicular part of
// c - s|^2 + L^2/12 (1 - (u . v)^2), cut at d^2 >= kVoteCutoff sigma^2 (vote_lut.hpp). Each
// term alone bounds d^2 from below, so an entry with a term at or over the cut cannot vote.
// The tests: the centre's whole perpendicular distance (its offsets along n and m, two unit
// directions across v) and the angle term, for four entries at once (KeptLanes; RulesOut is
// the same test for one entry). The cuts carry a margin for rounding, so the tests only save
// work: an entry they rule out would have voted 0.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "recog/hashing/line_direction_index.hpp"
#include "recog/hashing/vote_lut.hpp"

namespace sh {

struct LineLookUp {
  Eigen::Vector3f s, v;
  Eigen::Vector3f n, m;  // unit vectors perpendicular to v and to each other
  float n_dot_s = 0.0f, m_dot_s = 0.0f;
  float angle_cut_mm2 = 0.0f;  // L^2 (1 - cos^2 angle) at or above: no vote
  // (n . (centre - s))^2, and that plus (m . (centre - s))^2, at or above: no vote
  float offset_cut_mm2 = 0.0f;

  // The look-up of the line through support vector s along unit direction v, for votes of
  // width sigma (given as 1 / sigma^2, in 1/mm^2).
  static LineLookUp For(const Eigen::Vector3f& s, const Eigen::Vector3f& v, float inv_sigma2) {
    LineLookUp q;
    q.s = s;
    q.v = v;
    // n: across v, from the coordinate axis least aligned with it.
    const Eigen::Vector3f va = v.cwiseAbs();
    const int least = va.x() <= va.y() ? (va.x() <= va.z() ? 0 : 2) : (va.y() <= va.z() ? 1 : 2);
    q.n = v.cross(Eigen::Vector3f::Unit(least)).normalized();
    q.n_dot_s = q.n.dot(s);
    q.m = v.cross(q.n);
    q.m_dot_s = q.m.dot(s);
    // The vote's cut-offs, with a margin for rounding: the tests only save work, and the vote
    // (SegmentLineDistance2) sums its terms in another order.
    q.angle_cut_mm2 = 12.0f * float(kVoteCutoff) / inv_sigma2 * 1.01f;
    q.offset_cut_mm2 = float(kVoteCutoff) / inv_sigma2 * 1.01f + 0.25f;
    return q;
  }

  // The tests for four entries at once, both for every lane (no branch to mispredict: most
  // entries fail, in no order). Bit k set: entry k of the four may vote.
  unsigned KeptLanes(const LineDirectionIndex::Lanes& l) const {
    const Float4 offset = SplatFloat4(n.x()) * l.cx + SplatFloat4(n.y()) * l.cy +
                          SplatFloat4(n.z()) * l.cz - SplatFloat4(n_dot_s);
    const Float4 across = SplatFloat4(m.x()) * l.cx + SplatFloat4(m.y()) * l.cy +
                          SplatFloat4(m.z()) * l.cz - SplatFloat4(m_dot_s);
    const Float4 cos_angle =
        SplatFloat4(v.x()) * l.ux + SplatFloat4(v.y()) * l.uy + SplatFloat4(v.z()) * l.uz;
    const Float4 angle_term =
        l.length_mm * l.length_mm * (SplatFloat4(1.0f) - cos_angle * cos_angle);
    const Mask4 near = offset * offset + across * across < SplatFloat4(offset_cut_mm2);
    const Mask4 parallel = angle_term < SplatFloat4(angle_cut_mm2);
    return LaneBits(near & parallel);
  }

  // True when entry l cannot vote for the line: KeptLanes with l in its first lane.
  bool RulesOut(const LineDirectionIndex::Entry& l) const {
    const LineDirectionIndex::Lanes one = {{l.ux}, {l.uy}, {l.uz}, {l.length_mm},
                                           {l.cx}, {l.cy}, {l.cz}};
    return (KeptLanes(one) & 1u) == 0;
  }
};

}  // namespace sh
