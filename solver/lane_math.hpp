// Elementary functions of whole arrays, computed in lanes (lanes.hpp) by the
// same operations in every build, so that a run gives the same bits on any
// x86-64, whichever build the CPU picks.
//
// Why: a body force that turns with each particle's angle calls sin and cos
// once per particle per step (mms/ring.hpp), and libm's scalar sincos was a
// ninth of a CPDI step's instructions on the ring; the neo-Hookean stress
// takes ln J of every particle every step (material/neo_hookean_lanes.hpp).
#pragma once

#include <cstddef>

#include "lanes.hpp"

namespace mpmvv {

// Where |x| is at most this, sin and cos come from the lanes' reduction and
// polynomials (lane_math.cpp); beyond it, and for x not finite, from libm.
inline constexpr double kLaneSinCosLimit = 1.0e6;

// sin x_k and cos x_k for k < n, each within one unit in the last place of
// the exact value (tests/test_lane_math.cpp measures the largest error).
// `build` names a build the CPU has (cpu_has); by default the one the
// kernels run (lane_build).
void lane_sincos(std::size_t n, const double* x, double* sin_x, double* cos_x);
void lane_sincos(LaneBuild build, std::size_t n, const double* x, double* sin_x, double* cos_x);

// ln x_k for k < n, within one unit in the last place (lane_log.hpp; the
// same test measures it); libm's value where x_k is not positive, finite
// and normal.
void lane_log(std::size_t n, const double* x, double* log_x);
void lane_log(LaneBuild build, std::size_t n, const double* x, double* log_x);

// Each build's own, compiled for its instructions (solver/CMakeLists.txt).
// sincos_array tells whether any x_k lies past kLaneSinCosLimit or is NaN,
// log_array whether any x_k is not positive, finite and normal.
MPMVV_LANE_KERNEL(void sincos_array(std::size_t n, const double* x, double* sin_x, double* cos_x, bool& any_beyond))
MPMVV_LANE_KERNEL(void log_array(std::size_t n, const double* x, double* log_x, bool& any_outside))

}  // namespace mpmvv
