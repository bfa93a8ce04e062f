// Tracers for an external program that does not follow them: the probes'
// material points placed by mpmvv from the program's particles, so that the
// probe lines' L1 (eq. 3.1 of 000_1dbcb8acb6dddab9.txt) is measured for every
// code, not only for one that moves points with its grid velocity.
//
// The displacement u = x - X is fitted, in the reference configuration, by
// moving least squares with a quadratic basis (1, X, Y, X^2, XY, Y^2 about
// the tracer's reference point) over its kNearest nearest particles, weighted
// by (1 - (d / rho)^2)^2, rho a little past the farthest of them. The fit
// reproduces any quadratic displacement exactly, so what it adds to a tracer
// of a smooth motion is of the third order in the particle spacing s = h /
// ppd, and falls faster than the O(h^2) errors a convergence study of an MPM
// method measures (tests/test_tracer_interpolation.cpp measures both). It
// reads the particles as the program wrote them; no exact solution enters.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <vector>

#include "solver/tensor.hpp"

namespace mpmvv::app {

// A tracer the particles do not surround closely enough to fit: the message
// names it and what was found.
struct TracerInterpolationError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

inline constexpr std::size_t kTracerNeighbours = 24;

// The current positions of the material points `tracer_X` from particles at
// reference positions X and positions x (reference volumes V0 set the search
// scale, sqrt of their median: the particle spacing).
std::vector<Vec2> interpolated_tracers(const std::vector<Vec2>& X, const std::vector<Vec2>& x,
                                       const std::vector<double>& V0, const std::vector<Vec2>& tracer_X);

// What /external says of the method (its `tracers` attribute).
const char* tracer_interpolation_description();

}  // namespace mpmvv::app
