// π and the factors between degrees and radians, in float, the precision the board code computes
// angles in. Defined once so that every source of a module agrees on them, also when a unity
// build compiles the sources of a module as one.
#pragma once

namespace sh {

inline constexpr float kPi = 3.14159265358979f;
inline constexpr float kDegToRad = 0.017453292519943295f;
inline constexpr float kRadToDeg = 57.29577951308232f;

}  // namespace sh
