// Interest points and descriptors of one grey image (texture_features.hpp), with the image's
// Shi-Tomasi strength at full resolution kept for the stereo step.
//
// Per pyramid level k (kPyramidStep^k of the input size, each level blurred to
// level_sigma_px in its own pixels): central-difference gradients, the structure tensor
// integrated with a Gaussian of integration_sigma_px, the Harris response det - k trace^2, its
// local maxima above min_response (the strongest within the level's budget), orientation and
// descriptor from the level's gradients. Statically sized: one extractor holds kPlanes float
// planes of kMaxImagePixels (47 MiB): keep it in static storage or allocate it once at start-up.
// Extract() never allocates.
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"
#include "recog/image/image.hpp"
#include "recog/texture/descriptor.hpp"
#include "recog/texture/float_planes.hpp"
#include "recog/texture/parallel.hpp"
#include "recog/texture/texture_features.hpp"
#include "tables/feature_db_format.hpp"

namespace sh::texture {

struct TextureFeatureConfig {
  int levels = 6;                     // 1 .. kMaxPyramidLevels (fewer when the image gets small)
  float input_sigma_px = 0.5f;        // blur the input already has (optics, anti-aliasing)
  float level_sigma_px = 1.0f;        // blur of every level in its own pixels
  float integration_sigma_px = 1.0f;  // window of the structure tensor, level pixels
  float harris_k = 0.04f;
  // Harris response floor (intensities on [0, 1]); about a corner of contrast 0.1 (26 grey
  // levels) at the default scales.
  float min_response = 2e-7f;
  int nms_radius_px = 2;  // a maximum beats its (2 r + 1)^2 neighbourhood
  size_t max_keypoints = kMaxTextureKeypoints;
  OrientationConfig orientation;

  Status Validate() const;
};

// The settings stored in a feature database, and back. Recognition must extract its features
// with the settings the database was learnt with (max_keypoints is not stored).
TextureFeatureConfig ExtractionConfig(const FeatureDbExtraction& e);
FeatureDbExtraction ExtractionRecord(const TextureFeatureConfig& c);

// Largest Harris maxima considered per level before the budget selects the strongest.
inline constexpr size_t kMaxLevelCandidates = 4096;

// The planes and candidates are scratch that Extract() writes before it reads them: not zeroed
// (47 MiB) by design.
class TextureFeatureExtractor {  // NOLINT(cppcoreguidelines-pro-type-member-init)
 public:
  // Detects and describes the image's features; `out` is cleared first. Fails (leaving `out`
  // empty) on an empty or oversized image or an invalid configuration.
  // `parallel` spreads rows and keypoints over threads; the result does not depend on it.
  Status Extract(const ConstGrayView& image, const TextureFeatureConfig& config,
                 TextureFeatures* out, const ParallelFor& parallel = {});

  // Smaller eigenvalue of the level-0 structure tensor of the last image (Shi-Tomasi strength,
  // intensities on [0, 1]); valid until the next Extract().
  ConstFloatView min_eigenvalue() const { return {planes_[kMinEig], width_, height_, width_}; }

 private:
  struct Candidate {
    float response;
    int x, y;
  };
  enum Plane { kLevelA, kLevelB, kGx, kGy, kSxx, kSxy, kSyy, kTmp, kMinEig, kPlanes };

  FloatView plane(Plane p, int w, int h) { return PackedPlane(planes_[p], w, h); }
  // Harris maxima of the level in planes_[kSxx] (the response), strongest `budget` kept.
  size_t SelectMaxima(int w, int h, const TextureFeatureConfig& config, size_t budget,
                      TextureFeatureStats* stats);

  // One candidate's keypoints (one per orientation) and descriptors.
  struct Described {
    int n = 0;
    TextureKeypoint keypoints[kMaxPointOrientations];
    TextureDescriptor descriptors[kMaxPointOrientations];
  };
  template <typename Job>
  void DescribeCandidate(const Job& job, int i);

  int width_ = 0, height_ = 0;
  OrientationWindow orientation_window_;
  Described described_[kMaxTextureKeypoints];
  Candidate candidates_[kMaxLevelCandidates];
  float planes_[kPlanes][kMaxImagePixels];
};

}  // namespace sh::texture
