// The 3-D scene that stereo produces and geometric hashing consumes.
//
// Every 3-D feature remembers the 2-D features it was triangulated from (one in each image), so
// that once an object is recognised all 3-D features sharing a 2-D feature with it can be
// removed: they are either the object's own or spurious stereo matches of its image features.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "recog/base/vector.hpp"

namespace sh {

// Capacities of one scene. Stereo stops adding features when full and reports it.
inline constexpr size_t kMaxScenePoints = 2048;
inline constexpr size_t kMaxSceneLines = 2048;
inline constexpr uint16_t kNoFeature2d = 0xffff;

// Indices of the 2-D features (corners for points, lines for lines) in the left and right image.
struct FeatureSource {
  uint16_t left = kNoFeature2d;
  uint16_t right = kNoFeature2d;
};

struct ScenePoint {
  Eigen::Vector3f p_mm = Eigen::Vector3f::Zero();  // left-camera frame
  FeatureSource source;
  float quality = 0.0f;  // larger is more trustworthy (corner strength); used by basis ordering
};

// An infinite 3-D line, represented by the segment a_mm..b_mm of it that is supported by edge
// pixels in both images. Its direction is (b - a) / |b - a|.
struct SceneLine {
  Eigen::Vector3f a_mm = Eigen::Vector3f::Zero();
  Eigen::Vector3f b_mm = Eigen::Vector3f::Zero();
  FeatureSource source;
  float quality = 0.0f;  // larger is more trustworthy (supported length in mm by default)

  Eigen::Vector3f direction() const { return (b_mm - a_mm).normalized(); }
  float length_mm() const { return (b_mm - a_mm).norm(); }
};

struct Scene {
  Vector<ScenePoint, kMaxScenePoints> points;
  Vector<SceneLine, kMaxSceneLines> lines;

  void clear() {
    points.clear();
    lines.clear();
  }
};

}  // namespace sh
