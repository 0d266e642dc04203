#include "recog/image/binning.hpp"

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

// Sums one channel over the factor x factor block whose top-left pixel is (x0, y0).
template <typename Pixel, typename Channel>
uint32_t BlockSum(const ImageView<const Pixel>& src, int x0, int y0, int factor, Channel channel) {
  uint32_t sum = 0;
  for (int dy = 0; dy < factor; ++dy) {
    const Pixel* row = src.row(y0 + dy) + x0;
    for (int dx = 0; dx < factor; ++dx) sum += channel(row[dx]);
  }
  return sum;
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
  const uint32_t n = static_cast<uint32_t>(factor * factor);
  for (int y = 0; y < dst.height; ++y) {
    uint8_t* out = dst.row(y);
    for (int x = 0; x < dst.width; ++x) {
      const uint32_t sum =
          BlockSum(src, x * factor, y * factor, factor, [](uint8_t p) { return uint32_t{p}; });
      out[x] = static_cast<uint8_t>((sum + n / 2) / n);
    }
  }
  return Status::Ok();
}

Status BinRgb(ImageView<const Rgb8> src, int factor, ImageView<Rgb8> dst) {
  SH_RETURN_IF_ERROR(CheckBinnedShape(src.width, src.height, factor, dst.width, dst.height));
  const uint32_t n = static_cast<uint32_t>(factor * factor);
  for (int y = 0; y < dst.height; ++y) {
    Rgb8* out = dst.row(y);
    for (int x = 0; x < dst.width; ++x) {
      const int x0 = x * factor, y0 = y * factor;
      const uint32_t r = BlockSum(src, x0, y0, factor, [](Rgb8 p) { return uint32_t{p.r}; });
      const uint32_t g = BlockSum(src, x0, y0, factor, [](Rgb8 p) { return uint32_t{p.g}; });
      const uint32_t b = BlockSum(src, x0, y0, factor, [](Rgb8 p) { return uint32_t{p.b}; });
      out[x] = Rgb8{static_cast<uint8_t>((r + n / 2) / n), static_cast<uint8_t>((g + n / 2) / n),
                    static_cast<uint8_t>((b + n / 2) / n)};
    }
  }
  return Status::Ok();
}

}  // namespace sh
