#include "recog/shape/colour_classes.hpp"

#include <algorithm>
#include <cmath>

namespace sh {

Hsv RgbToHsv(float r, float g, float b) {
  const float mx = std::max(r, std::max(g, b));
  const float mn = std::min(r, std::min(g, b));
  const float c = mx - mn;
  Hsv out;
  out.v = mx;
  out.s = mx > 0 ? c / mx : 0.0f;
  if (c <= 0) return out;
  float h;
  if (mx == r) {
    h = 60.0f * (g - b) / c;
  } else if (mx == g) {
    h = 120.0f + 60.0f * (b - r) / c;
  } else {
    h = 240.0f + 60.0f * (r - g) / c;
  }
  out.h_deg = h < 0 ? h + 360.0f : h;
  return out;
}

float HueDistanceDeg(float a_deg, float b_deg) {
  const float d = std::fabs(std::fmod(a_deg - b_deg, 360.0f));
  return d > 180.0f ? 360.0f - d : d;
}

Status DeriveColourClasses(const float (*kd)[3], int n_models, ColourClassSet* out,
                           uint8_t* class_of_model) {
  *out = ColourClassSet{};
  for (int i = 0; i < n_models; ++i) {
    for (int k = 0; k < 3; ++k) {
      if (!(kd[i][k] >= 0.0f && kd[i][k] <= 1.0f)) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "model %d: diffuse colour component %g is outside 0..1", i,
                             static_cast<double>(kd[i][k]));
      }
    }
    const Hsv hsv = RgbToHsv(kd[i][0], kd[i][1], kd[i][2]);
    if (hsv.s < kMinModelSaturation || hsv.v <= 0.05f) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "model %d: colour (%.2f %.2f %.2f) has saturation %.2f, below the %.2f "
                           "that colour segmentation needs",
                           i, static_cast<double>(kd[i][0]), static_cast<double>(kd[i][1]),
                           static_cast<double>(kd[i][2]), static_cast<double>(hsv.s),
                           static_cast<double>(kMinModelSaturation));
    }
    int found = -1;
    for (int c = 0; c < out->n_classes; ++c) {
      const ColourClass& cc = out->classes[c];
      const Hsv other = RgbToHsv(cc.kd[0], cc.kd[1], cc.kd[2]);
      if (HueDistanceDeg(other.h_deg, hsv.h_deg) <= kSameColourHueDeg &&
          std::fabs(other.s - hsv.s) <= kSameColourSaturation) {
        found = c;
        break;
      }
    }
    if (found < 0) {
      if (out->n_classes == kMaxColourClasses) {
        return Status::Error(StatusCode::kResourceExhausted, "more than %d distinct part colours",
                             kMaxColourClasses);
      }
      found = out->n_classes++;
      ColourClass& cc = out->classes[found];
      for (int k = 0; k < 3; ++k) cc.kd[k] = kd[i][k];
      cc.hue_deg = hsv.h_deg;
      cc.min_saturation = kMinSaturationFraction * hsv.s;
    }
    class_of_model[i] = static_cast<uint8_t>(found + 1);
  }
  // Hue tolerances: a share of the gap to the nearest other class, at most the maximum.
  for (int c = 0; c < out->n_classes; ++c) {
    float gap = 360.0f;
    for (int d = 0; d < out->n_classes; ++d) {
      if (d != c) {
        gap = std::min(gap, HueDistanceDeg(out->classes[c].hue_deg, out->classes[d].hue_deg));
      }
    }
    out->classes[c].hue_tolerance_deg = std::min(kMaxHueToleranceDeg, kHueShareOfGap * gap);
  }
  return Status::Ok();
}

uint8_t ColourClassifier::ClassifyExact(const ColourClassSet& set, float r, float g, float b) {
  const float mx = std::max(r, std::max(g, b));
  const float mn = std::min(r, std::min(g, b));
  if (mx - mn < kMinChromaCodes) return kNoColourClass;
  const Hsv hsv = RgbToHsv(r, g, b);
  uint8_t best = kNoColourClass;
  float best_distance = 360.0f;
  for (int c = 0; c < set.n_classes; ++c) {
    const ColourClass& cc = set.classes[c];
    const float d = HueDistanceDeg(hsv.h_deg, cc.hue_deg);
    if (d <= cc.hue_tolerance_deg && hsv.s >= cc.min_saturation && d < best_distance) {
      best = static_cast<uint8_t>(c + 1);
      best_distance = d;
    }
  }
  return best;
}

Status ColourClassifier::Init(const ColourClassSet& set) {
  if (set.n_classes < 0 || set.n_classes > kMaxColourClasses) {
    return Status::Error(StatusCode::kInvalidArgument, "%d colour classes, expected 0..%d",
                         set.n_classes, kMaxColourClasses);
  }
  set_ = set;
  for (int r = 0; r < 32; ++r) {
    for (int g = 0; g < 32; ++g) {
      for (int b = 0; b < 32; ++b) {
        // Cell centre: code values 8 k .. 8 k + 7, centre 8 k + 3.5.
        lut_[(r << 10) | (g << 5) | b] =
            ClassifyExact(set, 8.0f * r + 3.5f, 8.0f * g + 3.5f, 8.0f * b + 3.5f);
      }
    }
  }
  return Status::Ok();
}

}  // namespace sh
