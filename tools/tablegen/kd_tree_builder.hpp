// Offline construction of the kd-tree of recog/texture/kd_tree.hpp over byte descriptors: each
// inner node splits its descriptors at the median of the component with the largest variance;
// leaves hold at most leaf_size descriptors (more only when they are all identical). Host only.
#pragma once

#include <cstdint>
#include <vector>

#include "recog/texture/kd_tree.hpp"

namespace sh {

// Builds the tree over `descriptors`. `order` receives the leaf order: the tree's leaves index
// the array descriptors[order[0]], descriptors[order[1]], ..., which the caller stores in that
// order. `depth` (may be null) receives the depth of the deepest leaf (root = 0).
void BuildKdTree(const std::vector<texture::TextureDescriptor>& descriptors, uint32_t leaf_size,
                 std::vector<texture::KdNode>* nodes, std::vector<uint32_t>* order,
                 uint32_t* depth);

}  // namespace sh
