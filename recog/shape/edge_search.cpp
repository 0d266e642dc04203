#include "recog/shape/edge_search.hpp"

#include <algorithm>
#include <cmath>

#include "recog/base/float4.hpp"

namespace sh {
namespace {

constexpr int kMaxSamples = 2 * kMaxEdgeSearchPx + 3;
static_assert(kMaxSamples + 1 <= 64, "one bit per sample in a 64-bit word, in blocks of four");

uint64_t Bit(int i) { return uint64_t{1} << i; }

float ColourDistance(const float* a, const float* b) {
  const float d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
  return std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
}

// Peak offset of a parabola through (-1, a), (0, b), (1, c), clamped to [-0.5, 0.5].
float ParabolaPeak(float a, float b, float c) {
  const float den = a - 2.0f * b + c;
  if (!(den < 0.0f)) return 0.0f;
  return std::max(-0.5f, std::min(0.5f, 0.5f * (a - c) / den));
}

}  // namespace

bool SampleRgb(ImageView<const Rgb8> image, float x, float y, float rgb[3]) {
  const int w = image.width, h = image.height;
  if (!(x >= 0.0f && y >= 0.0f && x <= w - 1.0f && y <= h - 1.0f) || w < 2 || h < 2) return false;
  const int x0 = std::min(static_cast<int>(x), w - 2);
  const int y0 = std::min(static_cast<int>(y), h - 2);
  const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
  const Rgb8* r0 = image.row(y0) + x0;
  const Rgb8* r1 = image.row(y0 + 1) + x0;
  const float wa = (1 - fx) * (1 - fy), wb = fx * (1 - fy), wc = (1 - fx) * fy, wd = fx * fy;
  rgb[0] = wa * r0[0].r + wb * r0[1].r + wc * r1[0].r + wd * r1[1].r;
  rgb[1] = wa * r0[0].g + wb * r0[1].g + wc * r1[0].g + wd * r1[1].g;
  rgb[2] = wa * r0[0].b + wb * r0[1].b + wc * r1[0].b + wd * r1[1].b;
  return true;
}

// The classes of all samples are read first, one bit per sample, without a branch: which side
// of an edge a sample falls on is what the search is for, so a branch on it is mispredicted
// about as often as not. The transitions that can hold an edge are then bit operations on those
// words, and only they read colours (bilinear, kept once read, as are their gradients).
//
// Candidates are examined from s = 0 outwards, and the search stops once no farther one can come
// nearer than the edge found: the transition i lies at |s| = d + 0.5 (d = i - range - 1 above the
// prediction, range - i below it), and its edge within a sample and a half of that (peak one
// sample away, parabola half a sample).
//
// Flattened: the lambdas and SampleRgb inlined into one body (it runs for every sample of every
// refinement pass).
[[gnu::flatten]] bool SearchEdge(ImageView<const Rgb8> image, ConstGrayView classes, uint8_t colour,
                                 bool silhouette, const Eigen::Vector2f& p,
                                 const Eigen::Vector2f& n, int range, float min_contrast,
                                 float* s_out) {
  if (range < 1 || range > kMaxEdgeSearchPx || image.empty() || classes.data == nullptr ||
      classes.width != image.width || classes.height != image.height) {
    return false;
  }
  const int count = 2 * range + 3;  // s = -range - 1 .. range + 1
  // SampleRgb's bounds: where a sample is valid its colour can be read.
  if (image.width < 2 || image.height < 2) return false;
  const float x_max = static_cast<float>(image.width) - 1.0f;
  const float y_max = static_cast<float>(image.height) - 1.0f;
  const float s_max = static_cast<float>(range + 1);
  uint64_t valid = 0, inside = 0;
  // Four samples at once (count + 1 <= 64: the last block's lanes stay within the word).
  const Float4 lane = {0.0f, 1.0f, 2.0f, 3.0f};
  for (int i = 0; i < count; i += kFloat4Lanes) {
    const Float4 s = SplatFloat4(static_cast<float>(i - range - 1)) + lane;
    const Float4 x = p.x() + s * n.x(), y = p.y() + s * n.y();
    const Mask4 v = (x >= 0.0f) & (y >= 0.0f) & (x <= x_max) & (y <= y_max) & (s <= s_max);
    // Invalid lanes read pixel (0, 0) and are masked. x, y >= 0 in the others: adding a half and
    // truncating is rounding to the nearest pixel.
    const Float4 zero = SplatFloat4(0.0f);
    const Float4 x_read = v ? x : zero, y_read = v ? y : zero;
    const Mask4 xi = __builtin_convertvector(x_read + 0.5f, Mask4);
    const Mask4 yi = __builtin_convertvector(y_read + 0.5f, Mask4);
    const unsigned v_bits = LaneBits(v);
    unsigned in_bits = 0;
    for (int k = 0; k < kFloat4Lanes; ++k) {
      in_bits |= static_cast<unsigned>(classes.at(xi[k], yi[k]) == colour) << k;
    }
    valid |= static_cast<uint64_t>(v_bits) << i;
    inside |= static_cast<uint64_t>(in_bits & v_bits) << i;
  }
  const uint64_t outside = valid & ~inside;
  // Bit i of a candidate word: the transition between samples i and i + 1, for i = 1 .. 2 range.
  uint64_t candidates = (Bit(2 * range + 1) - 1) & ~uint64_t{1};
  if (silhouette) {
    // Part colour on i, something else on i + 1; i - 1 not outside, i + 2 not inside.
    candidates &= inside & (outside >> 1) & ~(outside << 1) & ~(inside >> 2);
  } else {
    candidates &= inside & (inside >> 1);
  }
  if (candidates == 0) return false;

  float c[kMaxSamples][3];
  float gradient[kMaxSamples];
  uint64_t sampled = 0, graded = 0;  // bit i: c[i], gradient[i] hold
  const auto rgb = [&](int i) -> const float* {
    if ((sampled & Bit(i)) == 0) {
      const float s = static_cast<float>(i - range - 1);
      SampleRgb(image, p.x() + s * n.x(), p.y() + s * n.y(), c[i]);
      sampled |= Bit(i);
    }
    return c[i];
  };
  // Colour gradient between samples i and i + 1 (at s = i - range - 0.5); 0 where undefined.
  const auto g = [&](int i) -> float {
    if (i < 0 || i + 1 >= count || ((valid >> i) & 3) != 3) return 0.0f;
    if ((graded & Bit(i)) == 0) {
      gradient[i] = ColourDistance(rgb(i), rgb(i + 1));
      graded |= Bit(i);
    }
    return gradient[i];
  };
  // The edge of candidate transition i, if it has one.
  const auto edge_at = [&](int i, float* s) -> bool {
    int peak = i;
    float g_peak = g(i);
    if (silhouette) {
      // The classes switch where a blended pixel stops looking like the part, which for a dark
      // background is well past the middle of the blend: the edge is the gradient's peak next
      // to that switch.
      const float before = g(i - 1), after = g(i + 1);
      if (before > g_peak) peak = i - 1, g_peak = before;
      if (after > g_peak) peak = i + 1, g_peak = after;
      if (peak == 0 || peak + 1 >= count) return false;
    } else if (g_peak < g(i - 1) || g_peak < g(i + 1)) {
      return false;
    }
    if (g_peak < min_contrast) return false;
    *s = static_cast<float>(peak - range) - 0.5f + ParabolaPeak(g(peak - 1), g_peak, g(peak + 1));
    return true;
  };

  uint64_t above = candidates & ~(Bit(range + 1) - 1);  // i >= range + 1
  uint64_t below = candidates & (Bit(range + 1) - 1);   // i <= range
  float best = 0.0f;
  int best_i = -1;
  while ((above | below) != 0) {
    const int i_above = above != 0 ? __builtin_ctzll(above) : 2 * kMaxSamples;
    const int i_below = below != 0 ? 63 - __builtin_clzll(below) : -kMaxSamples;
    const int d_above = i_above - range - 1, d_below = range - i_below;
    int i, d;
    if (d_above <= d_below) {
      i = i_above, d = d_above;
      above &= above - 1;
    } else {
      i = i_below, d = d_below;
      below &= ~Bit(i);
    }
    if (best_i >= 0 && static_cast<float>(d) - 1.0f > std::fabs(best)) break;
    float s;
    if (!edge_at(i, &s)) continue;
    const float a = std::fabs(s), b = std::fabs(best);
    if (best_i < 0 || a < b || (a == b && i < best_i)) {
      best = s;
      best_i = i;
    }
  }
  if (best_i < 0) return false;
  *s_out = best;
  return true;
}

}  // namespace sh
