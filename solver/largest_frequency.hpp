// The largest frequency omega_max [rad/s] of an explicit step's grid motion,
// linearized about the particles' current state: central differences are
// stable while dt <= 2 / omega_max (time_loop.hpp: time_step = "stable"; the
// run-health figure's measured stable step, stable_step_iterations).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "grid.hpp"
#include "parallel.hpp"
#include "particles.hpp"
#include "stages.hpp"

namespace mpmvv {

// Power iteration on A u = M^-1 K u over grid displacements u, where K u is
// the internal force the grid displacement u takes away, found as the
// difference f(state) - f(state moved by u) with u a millionth of a cell:
// every particle moved and deformed by u as a step moves them (positions,
// F, CPDI domains, stress; eqs. 1.73-1.76), so the operator is the step's
// own linearization. The Rayleigh quotient u.Ku / u.Mu (M the lumped node
// masses) after the last iteration estimates omega_max^2 from below.
//
// bind(P) gives the stepper's shape over a particle set, walls(g) applies its
// walls to grid velocities, update_stresses(P) its materials' stresses from F.
template <class Bind, class Walls, class UpdateStresses>
double grid_largest_frequency(const Particles& P, const GridGeometry& grid, int iterations, Bind bind, Walls walls,
                              UpdateStresses update_stresses) {
  using Shape = decltype(bind(P));
  const std::size_t nodes = grid.node_count();
  ScatterBuffers buffers;
  buffers.resize(max_threads(), nodes);
  GridFields base;
  base.resize(nodes);
  particles_to_grid<kMass | kInternalForce>(bind(P), P, buffers, base);
  // Nodes a domain reaches by round-off only (a weight of order 1e-16) take
  // no part: the iterate u <- M^-1 K u would pile onto them, and a
  // perturbation of such a node changes no particle's state in floating point.
  double heaviest = 0.0;
  for (double m : base.mass) heaviest = std::max(heaviest, m);
  const double lightest = 1e-9 * heaviest;
  // A fixed start with every node and both axes in it: the result repeats.
  std::vector<Vec2> u(nodes, Vec2::Zero());
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  auto next = [&state] {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return double(state >> 11) * 0x1.0p-53 - 0.5;
  };
  for (std::size_t i = 0; i < nodes; ++i)
    if (base.mass[i] > lightest) u[i] = Vec2(next(), next());
  Particles moved = P;
  GridFields perturbed;
  perturbed.resize(nodes);
  double lambda = 0.0;
  for (int it = 0; it < iterations; ++it) {
    double largest = 0.0;
    for (const Vec2& v : u) largest = std::max(largest, v.cwiseAbs().maxCoeff());
    if (!(largest > 0.0)) return 0.0;
    const double eps = 1e-6 * grid.h / largest;
    for (std::size_t i = 0; i < nodes; ++i) {
      perturbed.velocity[i] = eps * u[i];
      perturbed.acceleration[i].setZero();
    }
    walls(perturbed);
    for (std::size_t i = 0; i < nodes; ++i) u[i] = perturbed.velocity[i] / eps;
    moved.position = P.position;
    moved.deformation_gradient = P.deformation_gradient;
    if constexpr (Shape::geometry == Geometry::axisymmetric) moved.hoop_stretch = P.hoop_stretch;
    grid_to_particles<kPosition | kDeformation, Shape>(bind(P), perturbed, moved, 1.0, 0.0);
    update_stresses(moved);
    particles_to_grid<kInternalForce>(bind(moved), moved, buffers, perturbed);
    double uKu = 0.0, uMu = 0.0;
    for (std::size_t i = 0; i < nodes; ++i) {
      if (!(base.mass[i] > lightest)) {
        u[i].setZero();
        continue;
      }
      const Vec2 Ku = (base.force[i] - perturbed.force[i]) / eps;
      uKu += u[i].dot(Ku);
      uMu += base.mass[i] * u[i].squaredNorm();
      u[i] = Ku / base.mass[i];
    }
    lambda = uKu / uMu;
    double size = 0.0;  // keep u of order one: lambda^iterations overflows
    for (const Vec2& v : u) size = std::max(size, v.cwiseAbs().maxCoeff());
    if (size > 0.0)
      for (Vec2& v : u) v /= size;
  }
  return std::sqrt(std::max(lambda, 0.0));
}

}  // namespace mpmvv
