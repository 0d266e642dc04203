#include "recog/texture/face_hough.hpp"

#include <algorithm>
#include <cmath>

namespace sh::texture {
namespace {

// Key layout: face (8 bits) | bin y + kOffset (12 bits) | bin x + kOffset (12 bits). Bins
// further than kOffset from the image origin (centres over 40,000 px away at r = 0.05) are not
// voted for.
constexpr int kOffset = 2048;
constexpr int kBinMask = 4095;

uint32_t MakeKey(uint32_t face, int bx, int by) {
  return (face << 24) | (static_cast<uint32_t>(by + kOffset) << 12) |
         static_cast<uint32_t>(bx + kOffset);
}
int KeyX(uint32_t key) { return static_cast<int>(key & kBinMask) - kOffset; }
int KeyY(uint32_t key) { return static_cast<int>((key >> 12) & kBinMask) - kOffset; }
uint32_t KeyFace(uint32_t key) { return key >> 24; }
bool InRange(int b) { return b >= -kOffset && b < kOffset; }

}  // namespace

void ScalesForCamera(double focal_px, double learnt_px_per_mm, double min_depth_mm,
                     double max_depth_mm, HoughConfig* config) {
  const double lo = focal_px / (max_depth_mm * learnt_px_per_mm);
  const double hi = focal_px / (min_depth_mm * learnt_px_per_mm);
  config->n_scales = kMaxHoughScales;
  for (int k = 0; k < kMaxHoughScales; ++k) {
    const double t = static_cast<double>(k) / (kMaxHoughScales - 1);
    config->scales[k] = static_cast<float>(lo * std::pow(hi / lo, t));
  }
}

void FaceHough::Vote(const HoughInput* inputs, size_t count, const HoughConfig& config) {
  n_votes_ = 0;
  const int n_scales = std::clamp(config.n_scales, 1, kMaxHoughScales);
  for (size_t i = 0; i < count && i <= UINT16_MAX; ++i) {
    const HoughInput& m = inputs[i];
    if (m.face > 255) continue;
    const float dphi = m.angle_rad - m.db_angle_rad;
    const float c = std::cos(dphi), s = std::sin(dphi);
    const float ru = c * m.u_px - s * m.v_px;
    const float rv = s * m.u_px + c * m.v_px;
    for (int k = 0; k < n_scales; ++k) {
      const float sk = config.scales[k];
      const int bx = static_cast<int>(std::floor(config.resolution * (m.x_px - sk * ru)));
      const int by = static_cast<int>(std::floor(config.resolution * (m.y_px - sk * rv)));
      if (!InRange(bx) || !InRange(by) || n_votes_ == kMaxHoughVotes) continue;
      votes_[n_votes_++] = {MakeKey(m.face, bx, by), static_cast<uint16_t>(i)};
    }
  }
  std::sort(votes_, votes_ + n_votes_, [](const Ballot& a, const Ballot& b) {
    return a.key < b.key || (a.key == b.key && a.match < b.match);
  });
  // One vote per (bin, match): a match's scales may fall into the same bin.
  size_t w = 0;
  for (size_t i = 0; i < n_votes_; ++i) {
    if (w > 0 && votes_[w - 1].key == votes_[i].key && votes_[w - 1].match == votes_[i].match)
      continue;
    votes_[w++] = votes_[i];
  }
  n_votes_ = w;
}

uint32_t FaceHough::BinCount(uint32_t key) const {
  const Ballot* end = votes_ + n_votes_;
  const Ballot* lo =
      std::lower_bound(votes_, end, key, [](const Ballot& b, uint32_t k) { return b.key < k; });
  const Ballot* hi = lo;
  while (hi < end && hi->key == key) ++hi;
  return static_cast<uint32_t>(hi - lo);
}

void FaceHough::ClusterMatches(const HoughCluster& cluster, Vector<uint16_t>& matches) const {
  matches.clear();
  const Ballot* end = votes_ + n_votes_;
  for (int dy = -1; dy <= 1; ++dy) {
    const int by = cluster.bin_y + dy;
    if (!InRange(by) || !InRange(cluster.bin_x - 1) || !InRange(cluster.bin_x + 1)) continue;
    // Bins x - 1 .. x + 1 of one row are consecutive keys.
    const uint32_t k0 = MakeKey(cluster.face, cluster.bin_x - 1, by);
    const uint32_t k1 = MakeKey(cluster.face, cluster.bin_x + 1, by);
    const Ballot* it =
        std::lower_bound(votes_, end, k0, [](const Ballot& b, uint32_t k) { return b.key < k; });
    for (; it < end && it->key <= k1; ++it) {
      if (!matches.push_back(it->match)) break;
    }
  }
  std::sort(matches.begin(), matches.end());
  size_t w = 0;
  for (size_t i = 0; i < matches.size(); ++i) {
    if (w == 0 || matches[w - 1] != matches[i]) matches[w++] = matches[i];
  }
  (void)matches.resize(w);
}

void FaceHough::Clusters(const HoughConfig& config, Vector<HoughCluster>& clusters) {
  clusters.clear();
  // Distinct-match counts of the 3 x 3 neighbourhoods, for every occupied bin; a cluster is a
  // bin whose own count is a local maximum (ties: the smaller key wins).
  Vector<uint16_t>& scratch = scratch_;
  for (size_t i = 0; i < n_votes_;) {
    const uint32_t key = votes_[i].key;
    size_t j = i;
    while (j < n_votes_ && votes_[j].key == key) ++j;
    const uint32_t own = static_cast<uint32_t>(j - i);
    i = j;
    bool is_max = true;
    const int bx = KeyX(key), by = KeyY(key);
    const uint32_t face = KeyFace(key);
    for (int dy = -1; dy <= 1 && is_max; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if ((dx == 0 && dy == 0) || !InRange(bx + dx) || !InRange(by + dy)) continue;
        const uint32_t nk = MakeKey(face, bx + dx, by + dy);
        const uint32_t n = BinCount(nk);
        if (n > own || (n == own && nk < key)) {
          is_max = false;
          break;
        }
      }
    }
    if (!is_max) continue;
    HoughCluster c;
    c.face = static_cast<uint16_t>(face);
    c.bin_x = bx;
    c.bin_y = by;
    ClusterMatches(c, scratch);
    if (scratch.size() < static_cast<size_t>(std::max(1, config.min_votes))) continue;
    c.votes = static_cast<uint16_t>(std::min<size_t>(scratch.size(), UINT16_MAX));
    if (!clusters.push_back(c)) {
      // Full: keep the strongest (replace the weakest if this one has more votes).
      size_t weakest = 0;
      for (size_t k = 1; k < clusters.size(); ++k) {
        if (clusters[k].votes < clusters[weakest].votes) weakest = k;
      }
      if (clusters[weakest].votes < c.votes) clusters[weakest] = c;
    }
  }
  std::sort(clusters.begin(), clusters.end(), [](const HoughCluster& a, const HoughCluster& b) {
    return a.votes > b.votes || (a.votes == b.votes && MakeKey(a.face, a.bin_x, a.bin_y) <
                                                           MakeKey(b.face, b.bin_x, b.bin_y));
  });
}

}  // namespace sh::texture
