// The exact solution's traction on a rectangle's sides, applied as the
// solver applies a traction (solver/traction.hpp): each boundary particle's
// domain side on the rectangle's boundary carries the nominal force
// integral of P(X, t) N dS over it, P from the exact motion. A manufactured
// motion whose boundary is not free of traction is then solved as a user's
// code would solve it, with the traction as a boundary condition.
#pragma once

#include <memory>

#include "mms/exact_solution.hpp"
#include "solver/particles.hpp"
#include "solver/traction.hpp"

namespace mpmvv::app {

// The sides of [lower, upper] by the domains of particles P: a particle's
// domain is its reference square X_p +- half (the seeding lattice's, or the
// particle's half_size where it has one), and a side of it that lies on the
// rectangle's boundary (to 1e-9 of the rectangle's size) is an edge.
// Throws std::invalid_argument when no particle's domain reaches a side.
std::shared_ptr<BoundaryTraction> exact_rectangle_traction(std::shared_ptr<const mms::ExactSolution> solution,
                                                           const Vec2& lower, const Vec2& upper, const Particles& P,
                                                           const Vec2& half);

}  // namespace mpmvv::app
