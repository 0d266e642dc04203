#include "tools/eval/image_degrade.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "hal/sim/world/rng.hpp"
#include "recog/image/gaussian.hpp"

namespace sh::tools {
namespace {

constexpr float kMaxNoiseSigma = 64.0f;
constexpr float kMinGain = 0.05f, kMaxGain = 20.0f;

// Defocus of one channel with the front end's own separable Gaussian (borders replicated):
// the rows of the 8-bit channel, then each output row from the filtered rows.
void BlurChannel(const GaussianKernel& k, int width, int height, const std::vector<uint8_t>& grey,
                 std::vector<float>& plane) {
  std::vector<float> rows(plane.size());
  const ImageView<float> filtered{rows.data(), width, height, width};
  FilterRows(ConstGrayView{grey.data(), width, height, width}, &k, filtered, nullptr, {}, nullptr,
             {});
  const ImageView<const float> in{rows.data(), width, height, width};
  for (int y = 0; y < height; ++y) {
    FilterColumnRow(in, k, y, &plane[static_cast<size_t>(y) * width]);
  }
}

}  // namespace

Status ValidateDegradation(const ImageDegradation& d) {
  if (!(d.noise_sigma >= 0.0f && d.noise_sigma <= kMaxNoiseSigma)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "noise sigma %g is outside 0..%g grey levels", d.noise_sigma,
                         kMaxNoiseSigma);
  }
  if (!(d.blur_sigma_px == 0.0f ||
        (d.blur_sigma_px >= kMinGaussianSigmaPx && d.blur_sigma_px <= kMaxGaussianSigmaPx))) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "blur sigma %g px is neither 0 nor in %g..%g", d.blur_sigma_px,
                         kMinGaussianSigmaPx, kMaxGaussianSigmaPx);
  }
  if (!(d.gain >= kMinGain && d.gain <= kMaxGain)) {
    return Status::Error(StatusCode::kInvalidArgument, "gain %g is outside %g..%g", d.gain,
                         kMinGain, kMaxGain);
  }
  return Status::Ok();
}

Status DegradeImage(const ImageDegradation& d, uint64_t seed, int width, int height, int channels,
                    uint8_t* pixels) {
  SH_RETURN_IF_ERROR(ValidateDegradation(d));
  if (width <= 0 || height <= 0 || channels <= 0 || channels > 4 || pixels == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "cannot degrade a %d x %d x %d image", width,
                         height, channels);
  }
  if (d.none()) return Status::Ok();
  GaussianKernel kernel;
  if (d.blur_sigma_px > 0.0f) SH_RETURN_IF_ERROR(MakeGaussianKernel(d.blur_sigma_px, 0, kernel));
  const size_t n = static_cast<size_t>(width) * height;
  // sigma^2 (1/2 + I/256): half read noise, half shot noise at mid grey.
  const float read_var = 0.5f * d.noise_sigma * d.noise_sigma;
  const float shot_var_per_level = d.noise_sigma * d.noise_sigma / 256.0f;
  std::vector<float> plane(n);
  std::vector<uint8_t> channel(n);
  for (int c = 0; c < channels; ++c) {
    for (size_t i = 0; i < n; ++i) channel[i] = pixels[i * channels + c];
    if (d.blur_sigma_px > 0.0f) {
      BlurChannel(kernel, width, height, channel, plane);
    } else {
      plane.assign(channel.begin(), channel.end());
    }
    const uint64_t stream = render::Mix64(seed ^ (0x51ed27u * static_cast<uint64_t>(c + 1)));
    for (size_t i = 0; i < n; ++i) {
      float v = std::min(255.0f, plane[i] * d.gain);
      if (d.noise_sigma > 0.0f) {
        const float sd = std::sqrt(read_var + shot_var_per_level * v);
        v += sd * render::GaussianFromHash(render::Mix64(stream + i));
      }
      pixels[i * channels + c] = static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 255.0f)));
    }
  }
  return Status::Ok();
}

uint64_t DegradationSeed(const char* scene_name, int camera) {
  uint64_t h = 0x6a09e667f3bcc909ull;  // each byte of the name folded in through the mixer
  for (const char* p = scene_name; *p != '\0'; ++p) {
    h = render::Mix64(h ^ static_cast<unsigned char>(*p));
  }
  return render::Mix64(h + static_cast<uint64_t>(camera));
}

}  // namespace sh::tools
