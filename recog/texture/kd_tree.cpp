#include "recog/texture/kd_tree.hpp"

#include <algorithm>
#include <cmath>

namespace sh::texture {
namespace {

// Keeps the k best neighbours, sorted by distance (insertion into a short array).
struct Best {
  KdNeighbour items[kMaxKdNeighbours];
  int n = 0;
  int k = 0;

  uint32_t worst() const { return n < k ? UINT32_MAX : items[n - 1].dist2; }
  void Offer(uint32_t index, uint32_t dist2) {
    if (dist2 >= worst()) return;
    int i = n < k ? n++ : n - 1;
    while (i > 0 && items[i - 1].dist2 > dist2) {
      items[i] = items[i - 1];
      --i;
    }
    items[i] = {index, dist2};
  }
};

}  // namespace

uint32_t DescriptorDistance2(const TextureDescriptor& a, const TextureDescriptor& b) {
  // 16-bit differences and 32-bit sums: the form SSE2 / NEON multiply-accumulate instructions
  // take, so the loop vectorises.
  uint32_t sum = 0;
  for (int i = 0; i < kDescriptorSize; ++i) {
    const int d = static_cast<int>(a.v[i]) - static_cast<int>(b.v[i]);
    sum += static_cast<uint32_t>(d * d);
  }
  return sum;
}

int KdSearcher::Search(const KdTreeView& tree, const TextureDescriptor& query, int k,
                       int max_checks, KdNeighbour* out) {
  ++stats_.queries;
  if (tree.n_nodes == 0 || k <= 0) return 0;
  Best best;
  best.k = std::min(k, kMaxKdNeighbours);
  int n_heap = 0;
  // Min-heap on the bound.
  auto heap_less = [](const Branch& a, const Branch& b) { return a.bound > b.bound; };
  auto remember = [&](uint32_t node, uint32_t bound) {
    if (n_heap == kMaxKdBranches) {
      ++stats_.branches_dropped;
      return;
    }
    heap_[n_heap++] = {node, bound};
    std::push_heap(heap_, heap_ + n_heap, heap_less);
  };
  int checks = 0;
  uint32_t node = 0;
  uint32_t bound = 0;
  for (;;) {
    // Descend from `node` to a leaf, remembering the other sides.
    while (!tree.nodes[node].leaf) {
      const KdNode& n = tree.nodes[node];
      const float diff = static_cast<float>(query.v[n.dim]) - n.split;
      // Anything on the far side differs by at least |diff| in this component.
      const uint32_t far_bound = std::max(bound, static_cast<uint32_t>(diff * diff));
      if (diff <= 0.0f) {
        remember(n.second, far_bound);
        node = n.first;
      } else {
        remember(n.first, far_bound);
        node = n.second;
      }
    }
    const KdNode& leaf = tree.nodes[node];
    for (uint32_t i = leaf.first; i < leaf.first + leaf.second; ++i) {
      best.Offer(i, DescriptorDistance2(query, tree.descriptors[i]));
    }
    checks += static_cast<int>(leaf.second);
    // Next: the remembered branch with the smallest bound, unless it cannot improve.
    bool found = false;
    while (n_heap > 0 && checks < max_checks) {
      std::pop_heap(heap_, heap_ + n_heap, heap_less);
      const Branch b = heap_[--n_heap];
      if (b.bound >= best.worst()) break;  // so is every other remembered branch
      node = b.node;
      bound = b.bound;
      found = true;
      break;
    }
    if (!found) break;
  }
  stats_.descriptors_compared += static_cast<uint64_t>(checks);
  for (int i = 0; i < best.n; ++i) out[i] = best.items[i];
  return best.n;
}

int BruteForceNeighbours(const KdTreeView& tree, const TextureDescriptor& query, int k,
                         KdNeighbour* out) {
  Best best;
  best.k = std::min(k, kMaxKdNeighbours);
  for (uint32_t i = 0; i < tree.n_descriptors; ++i) {
    best.Offer(i, DescriptorDistance2(query, tree.descriptors[i]));
  }
  for (int i = 0; i < best.n; ++i) out[i] = best.items[i];
  return best.n;
}

}  // namespace sh::texture
