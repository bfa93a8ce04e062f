// Constants a shape and its lane kernel share. A kernel's builds for AVX2
// and AVX-512 include nothing heavier than this and lanes.hpp, so that no
// inline function of a library is emitted with instructions the CPU may
// lack (solver/CMakeLists.txt).
#pragma once

namespace mpmvv {

// Natural coordinates of a domain's corners, counter-clockwise from (-1, -1).
inline constexpr double kCornerXi[4] = {-1.0, 1.0, 1.0, -1.0};
inline constexpr double kCornerEta[4] = {-1.0, -1.0, 1.0, 1.0};

// sqrt 2 - 1, rounded up: the octagon bound of a vector's length
// (stencil.hpp: entry_gradient_sum_bound).
inline constexpr double kOctagonFactor = 0.41421356237309515;

}  // namespace mpmvv
