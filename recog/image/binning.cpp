#include "recog/image/binning.hpp"

#include <cstddef>
#include <cstdint>

namespace sh {

Result<int> BinFactorFor(int width, int height) {
  if (width <= 0 || height <= 0 || width > kMaxSensorWidth || height > kMaxSensorHeight) {
    return Status::Error(StatusCode::kOutOfRange,
                         "image size %dx%d is outside the supported 1x1..%dx%d", width, height,
                         kMaxSensorWidth, kMaxSensorHeight);
  }
  for (int f = 1; f <= kMaxBinFactor; ++f) {
    if (BinnedSize(width, f) <= kMaxImageWidth && BinnedSize(height, f) <= kMaxImageHeight) {
      return f;
    }
  }
  // Unreachable while kMaxSensor* <= kMaxBinFactor * kMaxImage*; kept as a clear error.
  return Status::Error(StatusCode::kOutOfRange, "image size %dx%d needs a binning beyond %d", width,
                       height, kMaxBinFactor);
}

namespace {

Status CheckBinnedShape(int src_w, int src_h, int factor, int dst_w, int dst_h) {
  if (factor < 1 || factor > kMaxBinFactor) {
    return Status::Error(StatusCode::kInvalidArgument, "binning factor %d outside 1..%d", factor,
                         kMaxBinFactor);
  }
  if (dst_w != BinnedSize(src_w, factor) || dst_h != BinnedSize(src_h, factor) || dst_w <= 0 ||
      dst_h <= 0) {
    return Status::Error(
        StatusCode::kInvalidArgument, "binning %dx%d by %d gives %dx%d, not the %dx%d given", src_w,
        src_h, factor, BinnedSize(src_w, factor), BinnedSize(src_h, factor), dst_w, dst_h);
  }
  return Status::Ok();
}

// Block means of interleaved 8-bit pixels of `channels` bytes each (1 grey, 3 RGB), every
// channel apart; strides in bytes, dst_width x dst_height output pixels.
void BinInterleaved(const uint8_t* src, ptrdiff_t src_stride, uint8_t* dst, ptrdiff_t dst_stride,
                    int dst_width, int dst_height, int channels, int factor) {
  const uint32_t n = static_cast<uint32_t>(factor * factor);
  const ptrdiff_t block_bytes = static_cast<ptrdiff_t>(factor) * channels;
  for (int y = 0; y < dst_height; ++y) {
    const uint8_t* block_top = src + static_cast<ptrdiff_t>(y) * factor * src_stride;
    uint8_t* out = dst + (y * dst_stride);
    for (int x = 0; x < dst_width; ++x, block_top += block_bytes) {
      for (int c = 0; c < channels; ++c) {
        uint32_t sum = 0;
        for (int dy = 0; dy < factor; ++dy) {
          const uint8_t* row = block_top + (dy * src_stride) + c;
          for (int dx = 0; dx < factor; ++dx) sum += row[static_cast<ptrdiff_t>(dx) * channels];
        }
        *out++ = static_cast<uint8_t>((sum + n / 2) / n);
      }
    }
  }
}

// 2 x 2, every 5 MP sensor's factor: two rows at a time, which the compiler vectorises.
void BinGray2(ConstGrayView src, GrayView dst) {
  for (int y = 0; y < dst.height; ++y) {
    const uint8_t* top = src.row(2 * y);
    const uint8_t* bottom = src.row(2 * y + 1);
    uint8_t* out = dst.row(y);
    for (int x = 0; x < dst.width; ++x, top += 2, bottom += 2) {
      const unsigned sum = unsigned{top[0]} + top[1] + bottom[0] + bottom[1];
      out[x] = static_cast<uint8_t>((sum + 2) >> 2);
    }
  }
}

}  // namespace

Status BinGray(ConstGrayView src, int factor, GrayView dst) {
  SH_RETURN_IF_ERROR(CheckBinnedShape(src.width, src.height, factor, dst.width, dst.height));
  if (factor == 2) {
    BinGray2(src, dst);
    return Status::Ok();
  }
  BinInterleaved(src.data, src.stride, dst.data, dst.stride, dst.width, dst.height, 1, factor);
  return Status::Ok();
}

Status BinRgb(ImageView<const Rgb8> src, int factor, ImageView<Rgb8> dst) {
  SH_RETURN_IF_ERROR(CheckBinnedShape(src.width, src.height, factor, dst.width, dst.height));
  constexpr int kRgb = static_cast<int>(sizeof(Rgb8));
  BinInterleaved(reinterpret_cast<const uint8_t*>(src.data), src.stride * ptrdiff_t{kRgb},
                 reinterpret_cast<uint8_t*>(dst.data), dst.stride * ptrdiff_t{kRgb}, dst.width,
                 dst.height, kRgb, factor);
  return Status::Ok();
}

}  // namespace sh
