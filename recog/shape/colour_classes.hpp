// Colour classes of single-colour parts, derived from the models' diffuse colours (MTL Kd), and
// the per-pixel classifier that segments images into them (HSV, seed 001 section IV-A).
//
// A part's pixels keep the hue of its colour under any shading (a multiplicative change),
// and mostly keep its saturation: camera gamma lowers it (sRGB encoding takes Kd saturation
// 0.88 to about 0.6), highlights add white, shadowed faces add sensor noise. The table is grey
// (saturation near 0) and its mirror image of a part has a small fraction of the part's colour.
// So a pixel belongs to class c when
//   - its chroma max - min is at least kMinChromaCodes (sensor noise on dark pixels gives
//     random hues with small chroma),
//   - its saturation is at least kMinSaturationFraction of the class colour's,
//   - its hue lies within the class's hue tolerance: kMaxHueToleranceDeg, or less when another
//     class's hue is closer than twice that (each class gets kHueShareOfGap of the gap).
// Nothing is tuned per scene: all three follow from the model colours.
#pragma once

#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/image/image.hpp"

namespace sh {

inline constexpr int kMaxColourClasses = 8;   // distinct part colours in one model set
inline constexpr uint8_t kNoColourClass = 0;  // classifier output for table, shadow, grey

inline constexpr float kMinChromaCodes = 20.0f;        // max - min of R'G'B' code values
inline constexpr float kMinSaturationFraction = 0.3f;  // of the class colour's saturation
inline constexpr float kMaxHueToleranceDeg = 30.0f;
inline constexpr float kHueShareOfGap = 0.45f;      // of the hue gap to the nearest class
inline constexpr float kMinModelSaturation = 0.3f;  // greyer colours cannot be segmented
inline constexpr float kSameColourHueDeg = 4.0f;    // colours this close share a class
inline constexpr float kSameColourSaturation = 0.12f;

struct Hsv {
  float h_deg = 0;  // 0..360
  float s = 0;      // 0..1
  float v = 0;      // 0..1 (of the inputs' scale)
};

// rgb in any common scale (e.g. 0..1 or 0..255); v is in that scale.
Hsv RgbToHsv(float r, float g, float b);

// Absolute hue difference in degrees, 0..180.
float HueDistanceDeg(float a_deg, float b_deg);

struct ColourClass {
  float kd[3] = {0, 0, 0};  // the colour it was derived from (linear 0..1)
  float hue_deg = 0;
  float hue_tolerance_deg = 0;
  float min_saturation = 0;
};

struct ColourClassSet {
  int n_classes = 0;
  ColourClass classes[kMaxColourClasses];  // class id c is classes[c - 1]
};

// Groups the model colours `kd[i]` (linear RGB 0..1) into classes and derives each class's
// thresholds; class_of_model[i] receives the class id (1..n_classes) of model i. Errors: a
// colour too grey to segment (kInvalidArgument, naming the model index), more than
// kMaxColourClasses distinct colours (kResourceExhausted).
Status DeriveColourClasses(const float (*kd)[3], int n_models, ColourClassSet* out,
                           uint8_t* class_of_model);

// Per-pixel classifier: a 32 x 32 x 32 look-up table over the top five bits of R', G', B',
// evaluated at each cell's centre (32 KiB, stays in the first-level cache).
class ColourClassifier {
 public:
  Status Init(const ColourClassSet& set);
  uint8_t Classify(Rgb8 p) const {
    return lut_[(static_cast<unsigned>(p.r >> 3) << 10) | (static_cast<unsigned>(p.g >> 3) << 5) |
                (p.b >> 3)];
  }
  const ColourClassSet& classes() const { return set_; }

  // The rule the table is built from, for any R'G'B' code values.
  static uint8_t ClassifyExact(const ColourClassSet& set, float r, float g, float b);

 private:
  ColourClassSet set_;
  uint8_t lut_[32 * 32 * 32] = {};
};

}  // namespace sh
