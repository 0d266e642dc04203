// Four floats in one register: SSE on x86-64, NEON on AArch64, through the compiler's vector
// extension (GCC and Clang), so that one source serves the board and the host without
// intrinsics. Arithmetic and comparisons work lane by lane; a comparison gives a lane of all
// ones where it holds and zero where not.
#pragma once

#include <cstdint>
#include <cstring>

namespace sh {

inline constexpr int kFloat4Lanes = 4;

using Float4 = float __attribute__((vector_size(16)));
using Mask4 = int32_t __attribute__((vector_size(16)));

// Four consecutive floats from any address (no alignment needed).
inline Float4 LoadFloat4(const float* p) {
  Float4 r;
  std::memcpy(&r, p, sizeof r);
  return r;
}

inline Float4 SplatFloat4(float x) { return Float4{x, x, x, x}; }

// Bit k set where lane k of the comparison held.
inline unsigned LaneBits(Mask4 m) {
  return unsigned(m[0] & 1) | unsigned(m[1] & 2) | unsigned(m[2] & 4) | unsigned(m[3] & 8);
}

}  // namespace sh
