// The scene bases the search tries, in the order of a policy: file order, a seeded shuffle, or
// quality (default). Quality order goes in two passes: first the bases with structural evidence
// (a connecting edge, corner-like points), sorted best first; when those are used up, all the
// others in scene order. The list is kept across objects, so a basis is never tried twice in one
// frame. Statically sized (kMaxSceneBases; a full list is truncated in its defined order).
#pragma once

#include <cstdint>

#include "recog/hashing/scene_state.hpp"
#include "recog/hashing/scene_topology.hpp"
#include "tables/table_format.hpp"

namespace sh {

inline constexpr size_t kMaxSceneBases = 32768;  // candidate scene bases held at once
// Spatial cells counted for the quality order's spread: a table of cells by their integer
// coordinates (open addressing). A scene spans far fewer (about 100 at 50 mm); a basis whose cell
// finds the table full, or whose position is not finite, loses no score.
inline constexpr size_t kBasisCellSlots = 1024;

enum class BasisOrder : uint8_t {
  kFileOrder,  // features in the order stereo produced them
  kRandom,     // seeded shuffle
  kQuality,    // bases whose features are connected by scene edges first, long lines first
};

// A scene basis by scene feature indices: (p0, p1, p2), (line, line) or (line, point).
struct SceneBasis {
  uint16_t f[3] = {0, 0, 0};
};

// Not zeroed on creation: scratch arrays, written before they are read.
class BasisCandidates {  // NOLINT(cppcoreguidelines-pro-type-member-init)
 public:
  struct Policy {
    BasisOrder order = BasisOrder::kQuality;
    uint32_t random_seed = 1;
    float connect_tolerance_mm = 2.5f;  // two-line bases: ends this close are connected
    // Quality order is spread over the scene: a basis loses this much score for each better
    // basis in its spatial cell (cubes of cell_size_mm around its first point), so that the
    // many bases of one busy region do not hide the best ones of a quiet region. 0: pure
    // quality order.
    float cell_rank_penalty = 0.0f;
    float cell_size_mm = 50.0f;
  };

  // The first list for a scene (quality order: the first pass, sorted).
  void Generate(const SceneState& state, const SceneTopology& topology, HashFunction hf,
                const BasisLimits& limits, const Policy& policy);
  // Quality order only: replaces the list with the second pass once the first is used up.
  // Returns false when every candidate was already generated.
  bool NextPass();

  uint32_t count() const { return count_; }
  const SceneBasis& operator[](uint32_t i) const { return candidates_[i]; }

 private:
  void Append(bool connected_only);
  // order_scratch_: the indices of the first count_ candidates by score_, best first.
  void SortOrder();
  // Position that places a basis in a spatial cell: its basis point, or its first line's middle.
  Eigen::Vector3f CellPosition(const SceneBasis& b) const;

  SceneState state_;
  const SceneTopology* topology_ = nullptr;
  HashFunction hf_ = HashFunction::kLinePointMidway;
  BasisLimits limits_;
  Policy policy_;
  bool all_generated_ = false;
  uint32_t count_ = 0;
  SceneBasis candidates_[kMaxSceneBases];
  float score_[kMaxSceneBases];
  uint32_t order_scratch_[kMaxSceneBases];
  SceneBasis sorted_scratch_[kMaxSceneBases];
  // The spread's cells: coordinates and the bases counted in each (count 0: empty slot).
  struct Cell {
    int32_t x = 0, y = 0, z = 0;
    uint16_t count = 0;
  };
  // The count of the basis's cell before it, and that count raised by one (a full table or a
  // position that is not finite: 0, nothing counted).
  uint16_t CountInCell(const Eigen::Vector3f& cell_position);
  Cell cells_[kBasisCellSlots];
};

}  // namespace sh
