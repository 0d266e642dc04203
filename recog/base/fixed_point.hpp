// Q-format fixed-point numbers with the scaling carried in the type.
//
// Q<I, F> holds a signed value with I integer bits (sign included) and F fraction bits in the
// smallest signed integer of I + F bits: raw = round(value * 2^F). UQ<I, F> is the unsigned
// counterpart. Conversions saturate at the type's range instead of wrapping, because a wrapped
// coordinate or vote silently corrupts a result while a saturated one stays bounded.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

namespace sh {

namespace detail {
template <int Bits, bool Signed>
struct FixedStorage;
template <>
struct FixedStorage<8, true> {
  using type = int8_t;
};
template <>
struct FixedStorage<16, true> {
  using type = int16_t;
};
template <>
struct FixedStorage<32, true> {
  using type = int32_t;
};
template <>
struct FixedStorage<8, false> {
  using type = uint8_t;
};
template <>
struct FixedStorage<16, false> {
  using type = uint16_t;
};
template <>
struct FixedStorage<32, false> {
  using type = uint32_t;
};

constexpr int RoundBits(int bits) { return bits <= 8 ? 8 : bits <= 16 ? 16 : 32; }
}  // namespace detail

template <int I, int F, bool Signed>
class FixedPoint {
 public:
  static_assert(I + F <= 32, "at most 32 bits");
  using Raw = typename detail::FixedStorage<detail::RoundBits(I + F), Signed>::type;
  static constexpr int kIntegerBits = I;
  static constexpr int kFractionBits = F;
  static constexpr double kScale = static_cast<double>(1ull << F);  // raw units per unit value
  static constexpr int64_t kRawMax =
      Signed ? (int64_t{1} << (I + F - 1)) - 1 : (int64_t{1} << (I + F)) - 1;
  static constexpr int64_t kRawMin = Signed ? -(int64_t{1} << (I + F - 1)) : 0;
  static constexpr double kMax = static_cast<double>(kRawMax) / kScale;
  static constexpr double kMin = static_cast<double>(kRawMin) / kScale;

  constexpr FixedPoint() = default;
  static constexpr FixedPoint FromRaw(Raw raw) {
    FixedPoint q;
    q.raw_ = raw;
    return q;
  }
  // value -> raw: multiply by 2^F, round to nearest, saturate to the representable range.
  // NaN maps to 0 so that a bad input cannot become an arbitrary bit pattern.
  static FixedPoint FromDouble(double value) {
    if (std::isnan(value)) return FromRaw(0);
    const double scaled = std::nearbyint(value * kScale);
    if (scaled >= static_cast<double>(kRawMax)) return FromRaw(static_cast<Raw>(kRawMax));
    if (scaled <= static_cast<double>(kRawMin)) return FromRaw(static_cast<Raw>(kRawMin));
    return FromRaw(static_cast<Raw>(scaled));
  }
  // raw -> value: divide by 2^F (exact in double for every raw value).
  constexpr double ToDouble() const { return static_cast<double>(raw_) / kScale; }
  constexpr float ToFloat() const { return static_cast<float>(raw_) * (1.0f / float(kScale)); }
  constexpr Raw raw() const { return raw_; }
  // True if value lies within the representable range (so FromDouble does not saturate).
  static bool Representable(double value) {
    return std::isfinite(value) && value * kScale <= static_cast<double>(kRawMax) + 0.5 &&
           value * kScale >= static_cast<double>(kRawMin) - 0.5;
  }

 private:
  Raw raw_ = 0;
};

template <int I, int F>
using Q = FixedPoint<I, F, true>;
template <int I, int F>
using UQ = FixedPoint<I, F, false>;

// The formats used across stereohash; each names what it holds.
using QCoordMm = Q<10, 6>;  // millimetres, +-512 mm, 1/64 mm resolution (table coordinates)
using QUnit = Q<2, 14>;     // unit-vector components and rotations, [-2, 2), 2^-14
using UQVote = UQ<0, 16>;   // a single Gaussian vote in [0, 1), 2^-16

}  // namespace sh
