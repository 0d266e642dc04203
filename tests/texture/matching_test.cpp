// Matching and clustering: the kd-tree against brute force, and the 2-D Hough vote of seed 001
// (eq. 2) on matches from known similarity transforms.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "recog/texture/face_hough.hpp"
#include "recog/texture/kd_tree.hpp"
#include "tools/tablegen/kd_tree_builder.hpp"

namespace sh::texture {
namespace {

// Descriptors around a few centres (as learnt features of several views of one point are).
std::vector<TextureDescriptor> ClusteredDescriptors(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<TextureDescriptor> centres(n / 5 + 1);
  for (TextureDescriptor& c : centres) {
    for (uint8_t& v : c.v) v = static_cast<uint8_t>(rng() % 120);
  }
  std::vector<TextureDescriptor> out(n);
  std::normal_distribution<float> noise(0.0f, 6.0f);
  for (int i = 0; i < n; ++i) {
    const TextureDescriptor& c = centres[static_cast<size_t>(i) % centres.size()];
    for (int k = 0; k < kDescriptorSize; ++k) {
      out[i].v[k] = static_cast<uint8_t>(std::clamp(c.v[k] + noise(rng), 0.0f, 255.0f));
    }
  }
  return out;
}

struct Tree {
  std::vector<KdNode> nodes;
  std::vector<TextureDescriptor> ordered;
  KdTreeView view() const {
    return {nodes.data(), static_cast<uint32_t>(nodes.size()), ordered.data(),
            static_cast<uint32_t>(ordered.size())};
  }
};

Tree Build(const std::vector<TextureDescriptor>& d, uint32_t leaf) {
  Tree t;
  std::vector<uint32_t> order;
  uint32_t depth = 0;
  BuildKdTree(d, leaf, &t.nodes, &order, &depth);
  for (uint32_t i : order) t.ordered.push_back(d[i]);
  return t;
}

TEST(KdTree, LeavesPartitionTheDescriptorsAndChildrenFollowTheirParent) {
  const std::vector<TextureDescriptor> d = ClusteredDescriptors(3000, 1);
  const Tree t = Build(d, 8);
  std::vector<int> covered(d.size(), 0);
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    const KdNode& n = t.nodes[i];
    if (n.leaf) {
      EXPECT_GE(n.second, 1u);
      EXPECT_LE(n.second, 8u);
      for (uint32_t k = n.first; k < n.first + n.second; ++k) ++covered[k];
    } else {
      EXPECT_GT(n.first, i);
      EXPECT_GT(n.second, i);
      EXPECT_LT(n.dim, kDescriptorSize);
    }
  }
  for (int c : covered) EXPECT_EQ(c, 1);
}

TEST(KdTree, UnboundedSearchEqualsBruteForce) {
  const std::vector<TextureDescriptor> d = ClusteredDescriptors(2000, 2);
  const Tree t = Build(d, 8);
  auto searcher = std::make_unique<KdSearcher>();
  const std::vector<TextureDescriptor> queries = ClusteredDescriptors(100, 3);
  for (const TextureDescriptor& q : queries) {
    KdNeighbour a[5], b[5];
    const int na = searcher->Search(t.view(), q, 5, 1 << 30, a);
    const int nb = BruteForceNeighbours(t.view(), q, 5, b);
    ASSERT_EQ(na, nb);
    for (int i = 0; i < na; ++i) EXPECT_EQ(a[i].dist2, b[i].dist2);
  }
}

TEST(KdTree, BestBinFirstFindsMostNearestNeighboursWithFewChecks) {
  const std::vector<TextureDescriptor> d = ClusteredDescriptors(8000, 4);
  const Tree t = Build(d, 8);
  auto searcher = std::make_unique<KdSearcher>();
  // Queries: perturbed copies of database descriptors (a scene feature near a learnt one).
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, 5.0f);
  int found = 0;
  constexpr int kQueries = 300;
  for (int i = 0; i < kQueries; ++i) {
    TextureDescriptor q = d[rng() % d.size()];
    for (uint8_t& v : q.v) v = static_cast<uint8_t>(std::clamp(v + noise(rng), 0.0f, 255.0f));
    KdNeighbour a[1], b[1];
    searcher->Search(t.view(), q, 1, 128, a);
    BruteForceNeighbours(t.view(), q, 1, b);
    found += a[0].dist2 == b[0].dist2 ? 1 : 0;
  }
  EXPECT_GT(found, kQueries * 8 / 10);
  EXPECT_LE(searcher->stats().descriptors_compared, uint64_t{kQueries} * (128 + 8));
}

TEST(KdTree, EmptyTreeFindsNothing) {
  auto searcher = std::make_unique<KdSearcher>();
  KdNeighbour out[2];
  EXPECT_EQ(searcher->Search(KdTreeView{}, TextureDescriptor{}, 2, 10, out), 0);
}

// Matches of one face instance seen at `centre`, scale s and turned by `angle`: the learnt
// feature at u' (relative to the face centre) appears at centre + s R u' with orientation
// phi' + angle.
void AddInstance(std::vector<HoughInput>& in, uint16_t face, Eigen::Vector2f centre, float s,
                 float angle, int n, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-150.0f, 150.0f), a(-3.0f, 3.0f);
  const float c = std::cos(angle), sn = std::sin(angle);
  for (int i = 0; i < n; ++i) {
    HoughInput m{};
    m.u_px = u(rng);
    m.v_px = u(rng);
    m.db_angle_rad = a(rng);
    m.angle_rad = m.db_angle_rad + angle;
    m.x_px = centre.x() + s * (c * m.u_px - sn * m.v_px);
    m.y_px = centre.y() + s * (sn * m.u_px + c * m.v_px);
    m.face = face;
    in.push_back(m);
  }
}

TEST(FaceHough, EachInstanceIsOneClusterHoldingItsMatches) {
  std::mt19937 rng(6);
  std::vector<HoughInput> in;
  AddInstance(in, 3, {300, 200}, 0.7f, 0.5f, 30, rng);   // matches 0..29
  AddInstance(in, 3, {560, 420}, 0.8f, -1.2f, 20, rng);  // another instance of the same face
  AddInstance(in, 7, {150, 450}, 0.55f, 2.5f, 12, rng);
  // Outliers: random positions and faces.
  std::uniform_real_distribution<float> px(0.0f, 700.0f), any(-3.0f, 3.0f);
  for (int i = 0; i < 60; ++i) {
    in.push_back({px(rng), px(rng), any(rng), px(rng) - 350, px(rng) - 350, any(rng),
                  static_cast<uint16_t>(rng() % 10)});
  }
  auto hough = std::make_unique<FaceHough>();
  HoughConfig config;
  hough->Vote(in.data(), in.size(), config);
  auto clusters = std::make_unique<Vector<HoughCluster, kMaxHoughClusters>>();
  hough->Clusters(config, *clusters);
  ASSERT_GE(clusters->size(), 3u);
  auto members = std::make_unique<Vector<uint16_t, 9 * kMaxTextureMatches>>();
  struct Expect {
    uint16_t face;
    Eigen::Vector2f centre;
    int first, count;
  };
  for (const Expect& e : {Expect{3, {300, 200}, 0, 30}, Expect{3, {560, 420}, 30, 20},
                          Expect{7, {150, 450}, 50, 12}}) {
    // The strongest cluster whose bin holds the centre (bins are 1 / r pixels wide).
    const HoughCluster* hit = nullptr;
    for (const HoughCluster& c : *clusters) {
      const Eigen::Vector2f bin_centre((c.bin_x + 0.5f) / config.resolution,
                                       (c.bin_y + 0.5f) / config.resolution);
      if (c.face == e.face && (bin_centre - e.centre).norm() < 1.5f / config.resolution) {
        hit = &c;
        break;
      }
    }
    ASSERT_NE(hit, nullptr) << "face " << e.face;
    hough->ClusterMatches(*hit, *members);
    int own = 0;
    for (uint16_t m : *members) own += (m >= e.first && m < e.first + e.count) ? 1 : 0;
    EXPECT_EQ(own, e.count) << "face " << e.face;
    EXPECT_GE(hit->votes, e.count);
  }
  // Most votes first.
  for (size_t i = 1; i < clusters->size(); ++i) {
    EXPECT_GE((*clusters)[i - 1].votes, (*clusters)[i].votes);
  }
}

TEST(FaceHough, ScatteredMatchesMakeNoCluster) {
  std::mt19937 rng(8);
  std::vector<HoughInput> in;
  in.reserve(40);
  std::uniform_real_distribution<float> px(0.0f, 700.0f), any(-3.0f, 3.0f);
  for (int i = 0; i < 40; ++i) {
    in.push_back({px(rng), px(rng), any(rng), px(rng) - 350, px(rng) - 350, any(rng),
                  static_cast<uint16_t>(i)});  // every match on its own face
  }
  auto hough = std::make_unique<FaceHough>();
  HoughConfig config;
  hough->Vote(in.data(), in.size(), config);
  auto clusters = std::make_unique<Vector<HoughCluster, kMaxHoughClusters>>();
  hough->Clusters(config, *clusters);
  EXPECT_TRUE(clusters->empty());
}

}  // namespace
}  // namespace sh::texture
