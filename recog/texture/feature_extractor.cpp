#include "recog/texture/feature_extractor.hpp"

#include <algorithm>
#include <cmath>

#include "recog/image/gaussian.hpp"

namespace sh::texture {
namespace {

// Sub-pixel offset of a maximum from three samples along one axis (parabola vertex), in
// [-0.5, 0.5].
float ParabolaOffset(float before, float at, float after) {
  const float denom = before - 2.0f * at + after;
  if (!(denom < 0.0f)) return 0.0f;
  return std::clamp(0.5f * (before - after) / denom, -0.5f, 0.5f);
}

bool Stronger(float response_a, int index_a, float response_b, int index_b) {
  // Ties broken by raster position so that the selection is deterministic.
  return response_a > response_b || (response_a == response_b && index_a < index_b);
}

}  // namespace

Status TextureFeatureConfig::Validate() const {
  if (levels < 1 || levels > kMaxPyramidLevels) {
    return Status::Error(StatusCode::kOutOfRange, "texture features: %d levels not in 1..%d",
                         levels, kMaxPyramidLevels);
  }
  if (!(input_sigma_px >= 0.0f && input_sigma_px < level_sigma_px)) {
    return Status::Error(StatusCode::kOutOfRange,
                         "texture features: input blur %.2f px must be in [0, level blur %.2f)",
                         static_cast<double>(input_sigma_px), static_cast<double>(level_sigma_px));
  }
  if (!(level_sigma_px >= kMinGaussianSigmaPx && level_sigma_px <= 3.0f)) {
    return Status::Error(
        StatusCode::kOutOfRange, "texture features: level blur %.2f px not in [%.1f, 3]",
        static_cast<double>(level_sigma_px), static_cast<double>(kMinGaussianSigmaPx));
  }
  if (!(integration_sigma_px >= kMinGaussianSigmaPx && integration_sigma_px <= 4.0f)) {
    return Status::Error(
        StatusCode::kOutOfRange, "texture features: integration scale %.2f px not in [%.1f, 4]",
        static_cast<double>(integration_sigma_px), static_cast<double>(kMinGaussianSigmaPx));
  }
  if (!(harris_k > 0.0f && harris_k < 0.25f) || !(min_response >= 0.0f)) {
    return Status::Error(StatusCode::kOutOfRange,
                         "texture features: Harris k %.3f not in (0, 0.25) or negative threshold",
                         static_cast<double>(harris_k));
  }
  if (nms_radius_px < 1 || nms_radius_px > 8) {
    return Status::Error(StatusCode::kOutOfRange, "texture features: NMS radius %d not in 1..8",
                         nms_radius_px);
  }
  if (max_keypoints < 1 || max_keypoints > kMaxTextureKeypoints) {
    return Status::Error(StatusCode::kOutOfRange, "texture features: %zu keypoints not in 1..%zu",
                         max_keypoints, kMaxTextureKeypoints);
  }
  if (orientation.max_orientations < 1 || orientation.max_orientations > kMaxPointOrientations ||
      !(orientation.secondary_ratio > 0.0f && orientation.secondary_ratio <= 1.0f) ||
      !(orientation.sigma_px >= 0.5f && orientation.sigma_px <= 6.0f)) {
    return Status::Error(StatusCode::kOutOfRange,
                         "texture features: orientation settings out of range (1..%d peaks, ratio "
                         "in (0, 1], sigma in [0.5, 6] px)",
                         kMaxPointOrientations);
  }
  return Status::Ok();
}

TextureFeatureConfig ExtractionConfig(const FeatureDbExtraction& e) {
  TextureFeatureConfig c;
  c.levels = static_cast<int>(std::min<uint32_t>(e.levels, 1000));
  c.input_sigma_px = e.input_sigma_px;
  c.level_sigma_px = e.level_sigma_px;
  c.integration_sigma_px = e.integration_sigma_px;
  c.harris_k = e.harris_k;
  c.min_response = e.min_response;
  c.nms_radius_px = static_cast<int>(std::min<uint32_t>(e.nms_radius_px, 1000));
  c.orientation.sigma_px = e.orientation_sigma_px;
  c.orientation.secondary_ratio = e.secondary_orientation_ratio;
  c.orientation.max_orientations = static_cast<int>(std::min<uint32_t>(e.max_orientations, 1000));
  return c;
}

FeatureDbExtraction ExtractionRecord(const TextureFeatureConfig& c) {
  FeatureDbExtraction e{};
  e.levels = static_cast<uint32_t>(c.levels);
  e.input_sigma_px = c.input_sigma_px;
  e.level_sigma_px = c.level_sigma_px;
  e.integration_sigma_px = c.integration_sigma_px;
  e.harris_k = c.harris_k;
  e.min_response = c.min_response;
  e.nms_radius_px = static_cast<uint32_t>(c.nms_radius_px);
  e.orientation_sigma_px = c.orientation.sigma_px;
  e.secondary_orientation_ratio = c.orientation.secondary_ratio;
  e.max_orientations = static_cast<uint32_t>(c.orientation.max_orientations);
  return e;
}

size_t TextureFeatureExtractor::SelectMaxima(int w, int h, const TextureFeatureConfig& config,
                                             size_t budget, TextureFeatureStats* stats) {
  const ConstFloatView r = plane(kSxx, w, h);
  const int nms = config.nms_radius_px;
  const int border = std::max(nms, DescriptorBorderPx());
  const size_t capacity = std::min({budget, kMaxLevelCandidates, kMaxTextureKeypoints});
  size_t n = 0;
  // Min-heap on response: the weakest kept candidate on top, replaced by stronger ones.
  auto weaker_first = [](const Candidate& a, const Candidate& b) {
    return Stronger(a.response, a.y * kMaxImageWidth + a.x, b.response, b.y * kMaxImageWidth + b.x);
  };
  for (int y = border; y < h - border; ++y) {
    const float* row = r.row(y);
    for (int x = border; x < w - border; ++x) {
      const float v = row[x];
      if (!(v > config.min_response)) continue;
      // Strict maximum over earlier neighbours, at least as large as later ones (one winner on
      // plateaus).
      bool is_max = true;
      for (int dy = -nms; dy <= nms && is_max; ++dy) {
        const float* nrow = r.row(y + dy);
        for (int dx = -nms; dx <= nms; ++dx) {
          if (dx == 0 && dy == 0) continue;
          const float u = nrow[x + dx];
          const bool earlier = dy < 0 || (dy == 0 && dx < 0);
          if (earlier ? u >= v : u > v) {
            is_max = false;
            break;
          }
        }
      }
      if (!is_max) continue;
      ++stats->maxima_found;
      const Candidate c{v, x, y};
      if (n < capacity) {
        candidates_[n++] = c;
        std::push_heap(candidates_, candidates_ + n, weaker_first);
      } else if (capacity > 0 && weaker_first(c, candidates_[0])) {
        std::pop_heap(candidates_, candidates_ + n, weaker_first);
        candidates_[n - 1] = c;
        std::push_heap(candidates_, candidates_ + n, weaker_first);
        ++stats->maxima_dropped;
      } else {
        ++stats->maxima_dropped;
      }
    }
  }
  // Strongest first.
  std::sort_heap(candidates_, candidates_ + n, weaker_first);
  return n;
}

template <typename Job>
void TextureFeatureExtractor::DescribeCandidate(const Job& j, int i) {
  const Candidate& c = candidates_[i];
  const ConstFloatView& r = j.response;
  const float x = c.x + ParabolaOffset(r.at(c.x - 1, c.y), c.response, r.at(c.x + 1, c.y));
  const float y = c.y + ParabolaOffset(r.at(c.x, c.y - 1), c.response, r.at(c.x, c.y + 1));
  float angles[kMaxPointOrientations];
  Described& d = described_[i];
  d.n = DominantOrientations(j.gx, j.gy, x, y, j.config->orientation, orientation_window_, angles);
  for (int a = 0; a < d.n; ++a) {
    TextureKeypoint& kp = d.keypoints[a];
    kp.x_px = x * j.to_level0;
    kp.y_px = y * j.to_level0;
    kp.angle_rad = angles[a];
    kp.scale = j.to_level0;
    kp.response = c.response;
    kp.level = static_cast<uint8_t>(j.level);
    ComputeDescriptor(j.gx, j.gy, x, y, angles[a], &d.descriptors[a]);
  }
}

Status TextureFeatureExtractor::Extract(const ConstGrayView& image,
                                        const TextureFeatureConfig& config, TextureFeatures* out,
                                        const ParallelFor& parallel) {
  out->clear();
  width_ = height_ = 0;
  SH_RETURN_IF_ERROR(ValidateGrayImage(image, "texture features"));
  SH_RETURN_IF_ERROR(config.Validate());

  GaussianKernel pre, step, integration;
  const float s = config.level_sigma_px;
  SH_RETURN_IF_ERROR(
      MakeGaussianKernel(std::max(kMinGaussianSigmaPx,
                                  std::sqrt(s * s - config.input_sigma_px * config.input_sigma_px)),
                         0, pre));
  // Blur that takes a level (sigma s in its pixels) to sigma s in the pixels of the next, smaller
  // level: s / step in the current pixels.
  const float s_next = s / kPyramidStep;
  SH_RETURN_IF_ERROR(MakeGaussianKernel(std::sqrt(s_next * s_next - s * s), 0, step));
  SH_RETURN_IF_ERROR(MakeGaussianKernel(config.integration_sigma_px, 0, integration));
  MakeOrientationWindow(config.orientation, &orientation_window_);

  // Level sizes and the keypoint budget of each (in proportion to its area).
  int widths[kMaxPyramidLevels], heights[kMaxPyramidLevels];
  const int min_size = 2 * DescriptorBorderPx() + 2 * config.nms_radius_px + 4;
  int levels = 0;
  double total_area = 0.0;
  int w = image.width, h = image.height;
  for (int k = 0; k < config.levels && w >= min_size && h >= min_size; ++k) {
    widths[k] = w;
    heights[k] = h;
    total_area += double{1.0} * w * h;
    ++levels;
    w = ResampledSize(w, kPyramidStep);
    h = ResampledSize(h, kPyramidStep);
  }
  width_ = image.width;
  height_ = image.height;
  out->stats.levels = static_cast<uint32_t>(levels);

  // Level 0: the input blurred to level_sigma_px.
  w = image.width;
  h = image.height;
  ToUnitFloat(image, plane(kGx, w, h));
  Plane current = kLevelA, next = kLevelB;
  BlurPlane(plane(kGx, w, h), pre, plane(kTmp, w, h), plane(current, w, h), parallel);
  if (levels == 0) {
    // Too small for keypoints; the Shi-Tomasi plane is still defined (all zero).
    std::fill(planes_[kMinEig], planes_[kMinEig] + size_t{1} * w * h, 0.0f);
    return Status::Ok();
  }

  size_t budget_carry = 0;
  for (int k = 0; k < levels; ++k) {
    w = widths[k];
    h = heights[k];
    const ConstFloatView level = plane(current, w, h);
    FloatView gx = plane(kGx, w, h), gy = plane(kGy, w, h);
    CentralGradients(level, gx, gy, parallel);
    // Structure tensor products, integrated.
    FloatView sxx = plane(kSxx, w, h), sxy = plane(kSxy, w, h), syy = plane(kSyy, w, h);
    ForRowBands(parallel, h, [&](int y0, int y1) {
      const size_t begin = size_t{1} * y0 * w, end = size_t{1} * y1 * w;
      const float* __restrict ax = gx.data;
      const float* __restrict ay = gy.data;
      float* __restrict pxx = sxx.data;
      float* __restrict pxy = sxy.data;
      float* __restrict pyy = syy.data;
      for (size_t i = begin; i < end; ++i) {
        pxx[i] = ax[i] * ax[i];
        pxy[i] = ax[i] * ay[i];
        pyy[i] = ay[i] * ay[i];
      }
    });
    FloatView tmp = plane(kTmp, w, h);
    BlurPlane(sxx, integration, tmp, sxx, parallel);
    BlurPlane(sxy, integration, tmp, sxy, parallel);
    BlurPlane(syy, integration, tmp, syy, parallel);
    const float hk = config.harris_k;
    ForRowBands(parallel, h, [&](int y0, int y1) {
      const size_t begin = size_t{1} * y0 * w, end = size_t{1} * y1 * w;
      float* __restrict pxx = sxx.data;
      const float* __restrict pxy = sxy.data;
      const float* __restrict pyy = syy.data;
      float* __restrict min_eig = planes_[kMinEig];
      for (size_t i = begin; i < end; ++i) {
        const float a = pxx[i], b = pxy[i], c = pyy[i];
        const float tr = a + c;
        if (k == 0) {
          const float d = a - c;
          min_eig[i] = 0.5f * (tr - std::sqrt(d * d + 4.0f * b * b));
        }
        pxx[i] = a * c - b * b - hk * tr * tr;  // Harris response replaces Sxx
      }
    });
    // Keypoints of this level.
    const size_t budget =
        static_cast<size_t>(config.max_keypoints * (double{1.0} * w * h) / total_area) +
        budget_carry;
    const size_t n_candidates = SelectMaxima(w, h, config, budget, &out->stats);
    // Orientations and descriptors of the candidates, spread over the threads (each writes its
    // own slot), then kept in candidate order while there is room.
    const float to_level0 = std::pow(1.0f / kPyramidStep, static_cast<float>(k));
    struct DescribeJob {
      TextureFeatureExtractor* self = nullptr;
      const TextureFeatureConfig* config = nullptr;
      ConstFloatView response, gx, gy;
      float to_level0 = 1.0f;
      int level = 0;
    } job{this, &config, plane(kSxx, w, h), gx, gy, to_level0, k};
    parallel(
        static_cast<int>(n_candidates),
        [](void* context, int i) {
          const auto& j = *static_cast<const DescribeJob*>(context);
          j.self->DescribeCandidate(j, i);
        },
        &job);
    size_t used = 0;
    for (size_t i = 0; i < n_candidates && !out->keypoints.full(); ++i) {
      const Described& d = described_[i];
      for (int a = 0; a < d.n; ++a) {
        if (!out->keypoints.push_back(d.keypoints[a])) break;
        (void)out->descriptors.push_back(d.descriptors[a]);  // same capacity as keypoints
        if (a > 0) ++out->stats.extra_orientations;
      }
      ++used;
    }
    budget_carry = budget > used ? budget - used : 0;
    if (out->keypoints.full())
      out->stats.maxima_dropped += static_cast<uint32_t>(n_candidates - used);

    // Next level: blur, then resample by kPyramidStep.
    if (k + 1 < levels) {
      BlurPlane(level, step, tmp, gx, parallel);
      ResampleBilinear(plane(kGx, w, h), kPyramidStep, plane(next, widths[k + 1], heights[k + 1]),
                       parallel);
      std::swap(current, next);
    }
  }
  return Status::Ok();
}

}  // namespace sh::texture
