#include "recog/shape/sampled_row_sad.hpp"

#include <cstddef>
#include <cstdlib>
#include <cstring>

namespace sh {
namespace {

using U8x16 = uint8_t __attribute__((vector_size(16)));
using U16x16 = uint16_t __attribute__((vector_size(32)));

U8x16 Load(const void* p) {
  U8x16 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// |a - b| byte by byte: the larger minus the smaller.
U8x16 AbsDiff(U8x16 a, U8x16 b) {
  const U8x16 a_larger = reinterpret_cast<U8x16>(a > b);
  return ((a - b) & a_larger) | ((b - a) & ~a_larger);
}

// A block is 16 pixels, of which the even ones are sampled: 48 bytes of RGB in three vectors,
// and 16 class bytes. Byte i of the RGB block belongs to pixel i / 3, sampled when that is even
// (i mod 6 < 3).
constexpr int kBlockPx = 16;
constexpr U8x16 kRgbKeep[3] = {{255, 255, 255, 0, 0, 0, 255, 255, 255, 0, 0, 0, 255, 255, 255, 0},
                               {0, 0, 255, 255, 255, 0, 0, 0, 255, 255, 255, 0, 0, 0, 255, 255},
                               {255, 0, 0, 0, 255, 255, 255, 0, 0, 0, 255, 255, 255, 0, 0, 0}};
static_assert(kMaxImageWidth / kBlockPx * 3 * 255 < 65536 && kMaxImageWidth / kBlockPx < 256,
              "a row's blocks must not overflow the 16-bit and 8-bit lane sums");
constexpr U8x16 kClassOne = {1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0};

}  // namespace

SampledRowSad SampleRowSad(const Rgb8* src, const Rgb8* dst, const uint8_t* dst_classes, int n,
                           uint8_t colour) {
  SampledRowSad out;
  // Whole blocks while the block's last pixel (odd, unsampled) is still inside the run's span
  // 0..2 (n - 1). Per block, a 16-bit lane of differences grows by at most 3 * 255 and a byte
  // lane of class matches by 1: the 80 blocks of the widest image row stay below 65,536 and 256.
  const int blocks = n >= kBlockPx / 2 + 1 ? (2 * (n - 1) - (kBlockPx - 1)) / kBlockPx + 1 : 0;
  U16x16 sad = {};
  U8x16 same = {};
  const U8x16 wanted = U8x16{} + colour;
  const auto* s = reinterpret_cast<const uint8_t*>(src);
  const auto* d = reinterpret_cast<const uint8_t*>(dst);
  for (int b = 0; b < blocks; ++b) {
    const size_t px = static_cast<size_t>(b) * kBlockPx;
    for (size_t k = 0; k < 3; ++k) {
      const U8x16 diff =
          AbsDiff(Load(s + 3 * px + 16 * k), Load(d + 3 * px + 16 * k)) & kRgbKeep[k];
      sad += __builtin_convertvector(diff, U16x16);
    }
    same += reinterpret_cast<U8x16>(Load(dst_classes + px) == wanted) & kClassOne;
  }
  for (int k = 0; k < 16; ++k) {
    out.sad += sad[k];
    out.same += same[k];
  }
  for (ptrdiff_t i = static_cast<ptrdiff_t>(blocks) * kBlockPx / 2; i < n; ++i) {
    const Rgb8& a = src[2 * i];
    const Rgb8& b = dst[2 * i];
    out.sad +=
        static_cast<uint32_t>(std::abs(a.r - b.r) + std::abs(a.g - b.g) + std::abs(a.b - b.b));
    out.same += dst_classes[2 * i] == colour;
  }
  return out;
}

}  // namespace sh
