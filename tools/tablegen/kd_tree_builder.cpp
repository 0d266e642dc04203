#include "tools/tablegen/kd_tree_builder.hpp"

#include <algorithm>
#include <numeric>

namespace sh {
namespace {

using texture::TextureDescriptor;

// Kd-tree over descriptors[order[begin .. end)], preorder into `nodes`; `order` is permuted so
// that every leaf covers a contiguous range.
uint32_t BuildKd(const std::vector<TextureDescriptor>& descriptors, std::vector<uint32_t>& order,
                 uint32_t begin, uint32_t end, uint32_t leaf_size, uint32_t depth,
                 std::vector<texture::KdNode>& nodes, uint32_t* max_depth) {
  const uint32_t index = static_cast<uint32_t>(nodes.size());
  nodes.emplace_back();
  *max_depth = std::max(*max_depth, depth);
  auto make_leaf = [&]() {
    texture::KdNode& n = nodes[index];
    n.leaf = 1;
    n.first = begin;
    n.second = end - begin;
    return index;
  };
  if (end - begin <= leaf_size) return make_leaf();
  // Split on the component of largest variance.
  double mean[texture::kDescriptorSize] = {}, var[texture::kDescriptorSize] = {};
  for (uint32_t i = begin; i < end; ++i) {
    const uint8_t* v = descriptors[order[i]].v;
    for (int d = 0; d < texture::kDescriptorSize; ++d) mean[d] += v[d];
  }
  const double count = end - begin;
  for (double& m : mean) m /= count;
  for (uint32_t i = begin; i < end; ++i) {
    const uint8_t* v = descriptors[order[i]].v;
    for (int d = 0; d < texture::kDescriptorSize; ++d)
      var[d] += (v[d] - mean[d]) * (v[d] - mean[d]);
  }
  const int dim = static_cast<int>(std::max_element(var, var + texture::kDescriptorSize) - var);
  if (var[dim] == 0.0) return make_leaf();  // identical descriptors
  auto value = [&](uint32_t i) { return descriptors[i].v[dim]; };
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                   [&](uint32_t a, uint32_t b) { return value(a) < value(b); });
  // Integer components: split at median - 0.5 (values below go left) or, when the median is
  // the smallest value, at median + 0.5; both sides are non-empty because the variance is not 0.
  int m = value(order[mid]);
  auto below = [&](uint32_t i) { return value(i) < m; };
  uint32_t split_at = static_cast<uint32_t>(
      std::partition(order.begin() + begin, order.begin() + end, below) - order.begin());
  float split = static_cast<float>(m) - 0.5f;
  if (split_at == begin) {
    split_at = static_cast<uint32_t>(std::partition(order.begin() + begin, order.begin() + end,
                                                    [&](uint32_t i) { return value(i) <= m; }) -
                                     order.begin());
    split = static_cast<float>(m) + 0.5f;
  }
  const uint32_t left =
      BuildKd(descriptors, order, begin, split_at, leaf_size, depth + 1, nodes, max_depth);
  const uint32_t right =
      BuildKd(descriptors, order, split_at, end, leaf_size, depth + 1, nodes, max_depth);
  texture::KdNode& n = nodes[index];
  n.leaf = 0;
  n.dim = static_cast<uint16_t>(dim);
  n.split = split;
  n.first = left;
  n.second = right;
  return index;
}

}  // namespace

void BuildKdTree(const std::vector<TextureDescriptor>& descriptors, uint32_t leaf_size,
                 std::vector<texture::KdNode>* nodes, std::vector<uint32_t>* order,
                 uint32_t* depth) {
  nodes->clear();
  order->resize(descriptors.size());
  std::iota(order->begin(), order->end(), 0u);
  uint32_t max_depth = 0;
  if (!descriptors.empty()) {
    BuildKd(descriptors, *order, 0, static_cast<uint32_t>(descriptors.size()),
            std::max<uint32_t>(1, leaf_size), 0, *nodes, &max_depth);
  }
  if (depth != nullptr) *depth = max_depth;
}

}  // namespace sh
