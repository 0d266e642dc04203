// 2-D Hough clustering of feature matches (seed 001, section V.B, eq. 2). A scene feature at
// u with orientation phi, matched to a learnt feature at u' (relative to its face's centre in
// its view) with orientation phi', votes for the face centre's image position
//
//     r [u - s_k R(phi - phi') u'],   s_k = 0.5 + 0.1 k, k = 0 .. 5,
//
// i.e. along a line segment over the scale range, in a 2-D space of resolution r per face (all
// views of a face vote in the same space, since their u' share the face centre). Instances are
// the maxima; a maximum's cluster is every match that voted in its 3 x 3 neighbourhood.
//
// Votes are kept as a sorted list of (face, bin) keys rather than as dense accumulators: a
// frame casts at most kMaxHoughVotes of them, while dense planes for every face would need
// megabytes.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/vector.hpp"
#include "recog/texture/texture_features.hpp"

namespace sh::texture {

inline constexpr int kMaxHoughScales = 8;
inline constexpr size_t kMaxTextureMatches = kMaxTextureKeypoints;
inline constexpr size_t kMaxHoughVotes = kMaxTextureMatches * kMaxHoughScales;
inline constexpr size_t kMaxHoughClusters = 256;

struct HoughConfig {
  float resolution = 0.05f;  // r: bins per image pixel
  int n_scales = 6;
  float scales[kMaxHoughScales] = {0.5f, 0.6f, 0.7f, 0.8f, 0.9f, 1.0f};  // s_k (the paper's)
  int min_votes = 5;  // distinct matches in a maximum's neighbourhood
};

// The scales s_k for a camera: a face at depth Z appears at about focal_px / Z image pixels per
// millimetre, the learnt views have learnt_px_per_mm, so faces between min_depth_mm and
// max_depth_mm appear at s in [focal / (max_depth ppm), focal / (min_depth ppm)]. The list
// spreads kMaxHoughScales scales evenly in log s over that range (the paper's 0.5 .. 1.0 in steps
// of 0.1 is its own camera's range at one resolution).
void ScalesForCamera(double focal_px, double learnt_px_per_mm, double min_depth_mm,
                     double max_depth_mm, HoughConfig* config);

// One match of a scene keypoint to a learnt feature, with what the vote needs.
struct HoughInput {
  float x_px, y_px, angle_rad;     // scene keypoint
  float u_px, v_px, db_angle_rad;  // learnt feature (view, relative to the face centre)
  uint16_t face;
};

struct HoughCluster {
  uint16_t face = 0;
  int bin_x = 0, bin_y = 0;  // of the maximum
  uint16_t votes = 0;        // distinct matches in the 3 x 3 neighbourhood
};

// The ballots are scratch that Vote() writes before anything reads them: not zeroed.
class FaceHough {  // NOLINT(cppcoreguidelines-pro-type-member-init)
 public:
  // Casts the votes of `inputs` (match i votes as i).
  void Vote(const HoughInput* inputs, size_t count, const HoughConfig& config);
  // Local maxima with at least min_votes, most votes first (at most kMaxHoughClusters).
  void Clusters(const HoughConfig& config, Vector<HoughCluster>& clusters);
  // The matches that voted in the 3 x 3 neighbourhood of the cluster's bin, each once, in
  // increasing order.
  void ClusterMatches(const HoughCluster& cluster, Vector<uint16_t>& matches) const;

  size_t vote_count() const { return n_votes_; }

 private:
  struct Ballot {
    uint32_t key;
    uint16_t match;
  };
  // Distinct matches in bin `key` (0 when empty).
  uint32_t BinCount(uint32_t key) const;

  Ballot votes_[kMaxHoughVotes];
  Vector<uint16_t, 9 * kMaxTextureMatches> scratch_;  // a cluster's matches
  size_t n_votes_ = 0;
};

}  // namespace sh::texture
