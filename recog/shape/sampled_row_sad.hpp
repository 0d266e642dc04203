// One row of the colour path's blob matching (ShapeRecognizer::BlobDepth): every other pixel of
// a run in one image against the pixels the same distance apart in the other.
#pragma once

#include <cstdint>

#include "recog/image/image.hpp"

namespace sh {

struct SampledRowSad {
  uint32_t sad = 0;   // sum over the pixels and their three channels of |src - dst|
  uint32_t same = 0;  // pixels whose class in the other image is `colour`
};

// Over the n pixels src[2 i], dst[2 i] and dst_classes[2 i] for i in 0..n - 1 (the pixels in
// between must be readable too: they lie inside the rows the runs come from). Sixteen pixels
// at a time in the compiler's byte vectors (SSE on the host, NEON on the board), the rest one
// by one; the sums are whole numbers, so they equal a plain loop's exactly.
SampledRowSad SampleRowSad(const Rgb8* src, const Rgb8* dst, const uint8_t* dst_classes, int n,
                           uint8_t colour);

}  // namespace sh
