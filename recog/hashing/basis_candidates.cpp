#include "recog/hashing/basis_candidates.hpp"

#include <algorithm>
#include <cmath>

#include "recog/hashing/basis.hpp"

namespace sh {
namespace {

uint32_t NextRandom(uint32_t& state) {  // xorshift32: deterministic on every platform
  state ^= state << 13;
  state ^= state >> 17;
  state ^= state << 5;
  return state;
}

}  // namespace

void BasisCandidates::Generate(const SceneState& state, const SceneTopology& topology,
                               HashFunction hf, const BasisLimits& limits, const Policy& policy) {
  state_ = state;
  topology_ = &topology;
  hf_ = hf;
  limits_ = limits;
  policy_ = policy;
  count_ = 0;
  all_generated_ = false;
  if (policy_.order == BasisOrder::kQuality) {
    Append(true);
    SortOrder();
    if (policy_.cell_rank_penalty > 0.0f) {
      // Each basis loses score for the better bases of its cell, then all are sorted again.
      std::fill(cells_, cells_ + kBasisCellSlots, Cell{});
      const float inv_cell = 1.0f / policy_.cell_size_mm;
      for (uint32_t k = 0; k < count_; ++k) {
        const uint32_t i = order_scratch_[k];
        const uint16_t rank = CountInCell(CellPosition(candidates_[i]) * inv_cell);
        score_[i] -= policy_.cell_rank_penalty * float(rank);
      }
      SortOrder();
    }
    SceneBasis* sorted = sorted_scratch_;
    for (uint32_t k = 0; k < count_; ++k) sorted[k] = candidates_[order_scratch_[k]];
    std::copy(sorted, sorted + count_, candidates_);
  } else {
    Append(false);
    all_generated_ = true;
    if (policy_.order == BasisOrder::kRandom) {
      uint32_t rng = policy_.random_seed ? policy_.random_seed : 1u;
      for (uint32_t i = count_; i > 1; --i)
        std::swap(candidates_[i - 1], candidates_[NextRandom(rng) % i]);
    }
  }
}

uint16_t BasisCandidates::CountInCell(const Eigen::Vector3f& cell_position) {
  // Cells within +-2^20 (50 km at 50 mm) fit int32 coordinates; beyond, or not finite: none.
  constexpr float kMaxCell = 1048576.0f;
  if (!cell_position.allFinite() || cell_position.cwiseAbs().maxCoeff() >= kMaxCell) return 0;
  const auto x = int32_t(std::floor(cell_position.x()));
  const auto y = int32_t(std::floor(cell_position.y()));
  const auto z = int32_t(std::floor(cell_position.z()));
  uint32_t slot = (uint32_t(x) * 73856093u ^ uint32_t(y) * 19349663u ^ uint32_t(z) * 83492791u) %
                  kBasisCellSlots;
  for (size_t probe = 0; probe < kBasisCellSlots; ++probe) {
    Cell& cell = cells_[slot];
    if (cell.count == 0) {
      cell = {x, y, z, 1};
      return 0;
    }
    if (cell.x == x && cell.y == y && cell.z == z) {
      const uint16_t rank = cell.count;
      if (cell.count < UINT16_MAX) ++cell.count;
      return rank;
    }
    slot = (slot + 1) % kBasisCellSlots;
  }
  return 0;  // the table is full
}

void BasisCandidates::SortOrder() {
  // Best first; equal scores keep scene order (deterministic). std::sort with the index as
  // tie-break, not std::stable_sort, which may allocate a temporary buffer.
  uint32_t* order = order_scratch_;
  for (uint32_t i = 0; i < count_; ++i) order[i] = i;
  std::sort(order, order + count_, [this](uint32_t a, uint32_t b) {
    if (score_[a] != score_[b]) return score_[a] > score_[b];
    return a < b;
  });
}

Eigen::Vector3f BasisCandidates::CellPosition(const SceneBasis& b) const {
  const Scene& s = *state_.scene;
  if (UsesLinePoint(hf_)) return s.points[b.f[1]].p_mm;
  if (hf_ == HashFunction::kTwoLines) return 0.5f * (s.lines[b.f[0]].a_mm + s.lines[b.f[0]].b_mm);
  return s.points[b.f[0]].p_mm;
}

bool BasisCandidates::NextPass() {
  if (all_generated_) return false;
  // Connected bases are used up: continue with all remaining ones.
  count_ = 0;
  Append(false);
  all_generated_ = true;
  return true;
}

void BasisCandidates::Append(bool connected_only) {
  const Scene& s = *state_.scene;
  const HashFunction hf = hf_;
  const BasisLimits& limits = limits_;
  const uint8_t* point_active = state_.point_active;
  const uint8_t* line_active = state_.line_active;
  const Eigen::Vector3f* line_dir = state_.line_dir;
  const SceneGrid& point_grid = *state_.point_grid;
  const SceneTopology& topology = *topology_;
  const int np = int(s.points.size()), nl = int(s.lines.size());
  auto add = [this](uint16_t a, uint16_t b, uint16_t c, float score) {
    if (count_ >= kMaxSceneBases) return false;
    candidates_[count_] = SceneBasis{{a, b, c}};
    score_[count_++] = score;
    return true;
  };
  if (UsesLinePoint(hf)) {
    for (int i = 0; i < nl; ++i) {
      if (!line_active[i]) continue;
      const BasisLine3 line{s.lines[i].a_mm, line_dir[i]};
      const float length = s.lines[i].length_mm();
      // A basis point of the same object lies within an object's size of the supported
      // segment (every model corner is within max_point_spacing_mm of every point of every
      // edge); farther points are not paired, whatever their distance to the infinite line.
      const Eigen::Vector3f mid = 0.5f * (s.lines[i].a_mm + s.lines[i].b_mm);
      const float reach = 0.5f * length + limits.max_point_spacing_mm;
      for (int j = 0; j < np; ++j) {
        if (!point_active[j] || (s.points[j].p_mm - mid).squaredNorm() > reach * reach) continue;
        const float d = PointLineDistance(line, s.points[j].p_mm);
        if (d < limits.min_point_line_mm || d > limits.max_point_line_mm) continue;
        // First pass: bases with structural evidence (a connecting edge, or at least a
        // corner-like point); second pass: the rest.
        const bool junction = topology.IsJunction(j);
        if (junction != connected_only) continue;
        // Object edges end in corners at both ends, object corners join two or three edges,
        // and an edge joins the basis line to the basis point; clutter rarely has all three.
        const float score = (topology.Connected(i, j) ? 40.0f : 0.0f) +
                            15.0f * float(std::min<int>(topology.IncidentCount(j), 3)) +
                            20.0f * float(topology.LineEndJoins(i)) +
                            std::min(length, 60.0f) / 6.0f;
        if (!add(uint16_t(i), uint16_t(j), 0, score)) return;
      }
    }
  } else if (hf == HashFunction::kTwoLines) {
    const float cos_limit = std::cos(limits.min_line_angle_deg * float(M_PI) / 180.0f);
    const float tol2 = policy_.connect_tolerance_mm * policy_.connect_tolerance_mm;
    for (int i = 0; i < nl; ++i) {
      if (!line_active[i]) continue;
      for (int j = 0; j < nl; ++j) {
        if (j == i || !line_active[j]) continue;
        if (std::fabs(line_dir[i].dot(line_dir[j])) > cos_limit) continue;
        const SceneLine &a = s.lines[i], &b = s.lines[j];
        const bool connected =
            std::min({(a.a_mm - b.a_mm).squaredNorm(), (a.a_mm - b.b_mm).squaredNorm(),
                      (a.b_mm - b.a_mm).squaredNorm(), (a.b_mm - b.b_mm).squaredNorm()}) <= tol2;
        if (connected != connected_only) continue;
        RigidTransform unused;
        if (!TwoLineFrame({a.a_mm, line_dir[i]}, {b.a_mm, line_dir[j]}, limits, &unused)) continue;
        const float score = std::min(a.length_mm(), 60.0f) + std::min(b.length_mm(), 60.0f);
        if (!add(uint16_t(i), uint16_t(j), 0, score)) return;
      }
    }
  } else {
    const float max_side = limits.max_point_spacing_mm;
    for (int i = 0; i < np; ++i) {
      if (!point_active[i]) continue;
      const Eigen::Vector3f& pi = s.points[i].p_mm;
      const bool junction_i = topology.IsJunction(i);
      if (connected_only && !junction_i) continue;
      bool full = false;
      point_grid.ForEachNear(pi, max_side, [&](int j) {
        if (full || j == i || !point_active[j]) return;
        const Eigen::Vector3f& pj = s.points[j].p_mm;
        point_grid.ForEachNear(pi, max_side, [&](int k) {
          if (full || k == i || k == j || !point_active[k]) return;
          const Eigen::Vector3f& pk = s.points[k].p_mm;
          const bool connected = junction_i && topology.IsJunction(j) && topology.IsJunction(k);
          if (connected != connected_only) return;
          RigidTransform unused;
          if (!ThreePointFrame(hf, pi, pj, pk, limits, &unused)) return;
          // Corners joined by edges first: a line incident to both ends of a side.
          auto joined = [&topology](int a, int b) {
            for (int x = 0; x < topology.IncidentCount(a); ++x) {
              for (int y = 0; y < topology.IncidentCount(b); ++y) {
                if (topology.IncidentLine(a, x) == topology.IncidentLine(b, y)) return 1;
              }
            }
            return 0;
          };
          const float score = 40.0f * float(joined(i, j) + joined(i, k) + joined(j, k)) +
                              5.0f * float(topology.IncidentCount(i) + topology.IncidentCount(j) +
                                           topology.IncidentCount(k)) +
                              0.01f * ((pj - pi).norm() + (pk - pi).norm());
          full = !add(uint16_t(i), uint16_t(j), uint16_t(k), score);
        });
      });
      if (full) return;
    }
  }
}

}  // namespace sh
