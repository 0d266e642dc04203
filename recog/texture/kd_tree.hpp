// Nearest-neighbour search over byte descriptors with a kd-tree and best-bin-first (Beis & Lowe
// 1997): the tree is built offline and stored in the feature database; a query descends to a
// leaf, remembers the branches it passed with a lower bound of their distance, and then visits
// the most promising remembered branches until max_checks descriptors have been compared.
// The tree's layout (KdNode, KdTreeView) is part of the database format:
// tables/texture_records.hpp.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/texture/texture_features.hpp"
#include "tables/texture_records.hpp"

namespace sh::texture {

// Squared Euclidean distance between two descriptors.
uint32_t DescriptorDistance2(const TextureDescriptor& a, const TextureDescriptor& b);

struct KdNeighbour {
  uint32_t index = 0;  // into the descriptor array
  uint32_t dist2 = 0;
};

// Branches remembered during one query; when full, further branches are not remembered (the
// search then explores fewer bins, a defined loss of recall counted in KdSearchStats).
inline constexpr int kMaxKdBranches = 1024;
inline constexpr int kMaxKdNeighbours = 16;

struct KdSearchStats {
  uint64_t queries = 0;
  uint64_t descriptors_compared = 0;
  uint64_t branches_dropped = 0;
};

// Holds the branch queue of a query (no heap); one per thread. The queue is scratch written
// before it is read: not zeroed.
class KdSearcher {  // NOLINT(cppcoreguidelines-pro-type-member-init)
 public:
  // The k (<= kMaxKdNeighbours) nearest of the descriptors compared, closest first, written to
  // `out`; returns how many (fewer when the tree is small). max_checks bounds the descriptors
  // compared (at least one leaf is always searched completely).
  int Search(const KdTreeView& tree, const TextureDescriptor& query, int k, int max_checks,
             KdNeighbour* out);

  const KdSearchStats& stats() const { return stats_; }
  void ResetStats() { stats_ = {}; }

 private:
  struct Branch {
    uint32_t node;
    uint32_t bound;  // lower bound of the squared distance of anything under `node`
  };
  Branch heap_[kMaxKdBranches];
  KdSearchStats stats_;
};

// Exhaustive reference of Search (tests, the builder's recall figures).
int BruteForceNeighbours(const KdTreeView& tree, const TextureDescriptor& query, int k,
                         KdNeighbour* out);

}  // namespace sh::texture
