// The records of the texture path that the feature database stores and its reader validates:
// the descriptor (Lowe's 4 x 4 cells x 8 orientations, as bytes), the pyramid levels a feature
// may come from, and the kd-tree's node layout. recog/texture extracts and searches them
// (texture_features.hpp, kd_tree.hpp); tools/tablegen learns and writes them.
//
// Tree layout: KdNode[0] is the root. An inner node splits on one descriptor component: queries
// with component <= split go to `first` (the left child), others to `second` (the right child);
// both children have larger indices than their parent. A leaf holds descriptors
// [first, first + second) of the database's descriptor array.
#pragma once

#include <cstdint>

namespace sh {

// Level k of the feature pyramid has kPyramidStep^k of the input's resolution (texture_features).
inline constexpr int kMaxPyramidLevels = 8;

inline constexpr int kDescriptorCells = 4;         // cells per side
inline constexpr int kDescriptorOrientations = 8;  // orientation bins per cell
inline constexpr int kDescriptorSize =
    kDescriptorCells * kDescriptorCells * kDescriptorOrientations;

struct alignas(16) TextureDescriptor {
  uint8_t v[kDescriptorSize] = {};
};
static_assert(sizeof(TextureDescriptor) == 128, "stored in the feature database");

struct KdNode {
  uint32_t first = 0;   // inner: left child; leaf: first descriptor
  uint32_t second = 0;  // inner: right child; leaf: descriptor count
  uint16_t dim = 0;     // inner: split component (0 .. kDescriptorSize - 1)
  uint16_t leaf = 0;    // 1 for a leaf
  float split = 0.0f;   // inner: threshold on the component
};
static_assert(sizeof(KdNode) == 16, "stored in the feature database");

// A tree over a descriptor array, as the database holds them.
struct KdTreeView {
  const KdNode* nodes = nullptr;
  uint32_t n_nodes = 0;
  const TextureDescriptor* descriptors = nullptr;
  uint32_t n_descriptors = 0;
};

// The texture path's own code names these in its namespace.
namespace texture {
using ::sh::kDescriptorCells;
using ::sh::kDescriptorOrientations;
using ::sh::kDescriptorSize;
using ::sh::KdNode;
using ::sh::KdTreeView;
using ::sh::kMaxPyramidLevels;
using ::sh::TextureDescriptor;
}  // namespace texture

}  // namespace sh
