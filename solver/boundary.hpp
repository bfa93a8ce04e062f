// Boundary conditions a scene may add to the step: prescribed motion of grid
// nodes, dead-load tractions on boundary particles, and grid damping for
// dynamic relaxation (002_c3305cb8b1bc1490.txt sections 1.4 and 1.4.1). A
// scene that names none of them runs without them: nothing here is allocated
// or visited.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "contact.hpp"
#include "grid.hpp"
#include "model.hpp"
#include "parallel.hpp"
#include "particles.hpp"
#include "traction.hpp"

namespace mpmvv {

// ---------------------------------------------------------------- prescribed node motion

// One displacement component prescribed at a set of grid nodes: u_axis(t),
// with u(0) = 0. Over a step from t to t + dt a constrained node moves with
// v = (u(t + dt) - u(t)) / dt, so the nodes follow u exactly at the step ends
// whatever the time integration. Applied after the walls: it overrides them on
// the nodes it names.
struct NodeConstraint {
  std::vector<std::size_t> nodes;
  int axis = 0;                                 // 0: x, 1: y
  std::function<double(double)> displacement;   // u(t) [m]
};

// Sets the constrained components (velocity, and the acceleration that takes
// the velocity before the kick to it) and returns, per constraint, the
// reaction: the force the constraint adds to the grid along its axis,
// sum_g (m_g a_g - f_g) over its nodes [N per unit depth].
inline std::vector<double> apply_constraints(const std::vector<NodeConstraint>& constraints, double t, double dt,
                                             double kick, GridFields& g) {
  std::vector<double> reactions;
  reactions.reserve(constraints.size());
  for (const NodeConstraint& c : constraints) {
    const double v = (c.displacement(t + dt) - c.displacement(t)) / dt;
    double reaction = 0.0;
    for (std::size_t i : c.nodes) {
      const int a = c.axis;
      const double m = g.mass[i];
      const double before = m > 0.0 ? g.momentum[i][a] / m : 0.0;
      g.velocity[i][a] = v;
      g.acceleration[i][a] = (v - before) / kick;
      if (m > 0.0) reaction += m * g.acceleration[i][a] - g.force[i][a];
    }
    reactions.push_back(reaction);
  }
  return reactions;
}

// Two flags per grid node (x, y): 1 where a constraint prescribes the component.
inline std::vector<unsigned char> prescribed_components(std::size_t nodes,
                                                        const std::vector<NodeConstraint>& constraints) {
  std::vector<unsigned char> fixed(2 * nodes, 0);
  for (const NodeConstraint& c : constraints)
    for (std::size_t node : c.nodes) fixed[2 * node + std::size_t(c.axis)] = 1;
  return fixed;
}

// ---------------------------------------------------------------- tractions

// A dead load on boundary particles (eq. 1.64, f_g^ext = sum_p f_p S_gp): each
// loaded particle p carries the force traction(t) * reference_area_p along
// `direction`, where reference_area_p is the length of the loaded face of its
// reference domain (per unit depth). The force enters the grid as m_p b_p with
// b_p = f_p / m_p, through the same transfer as a body force.
class SurfaceTraction final : public BodyForce {
 public:
  SurfaceTraction(std::vector<std::size_t> particles, std::vector<double> reference_area, Vec2 direction,
                  std::function<double(double)> traction)
      : particles_(std::move(particles)),
        reference_area_(std::move(reference_area)),
        direction_(direction),
        traction_(std::move(traction)) {}

  void evaluate(double t, const Particles& P, std::vector<Vec2>& b) const override {
    // b is zero from its allocation and only loaded particles are written.
    const double traction = traction_(t);
    for (std::size_t k = 0; k < particles_.size(); ++k) {
      const std::size_t p = particles_[k];
      b[p] = traction * reference_area_[k] / P.mass[p] * direction_;
    }
  }

  std::size_t bytes() const override { return bytes_held(particles_) + bytes_held(reference_area_); }

  double total_force(double t) const {
    double area = 0.0;
    for (double a : reference_area_) area += a;
    return traction_(t) * area;
  }

 private:
  std::vector<std::size_t> particles_;
  std::vector<double> reference_area_;
  Vec2 direction_;
  std::function<double(double)> traction_;
};

// ---------------------------------------------------------------- damping

// Mass-proportional grid damping, eq. 1.65 with alpha_d = zeta m_g:
// a_g = f_g / m_g - zeta v_g, v_g the velocity before the kick. Dynamic
// relaxation: with zeta twice the lowest angular frequency the lowest mode is
// critically damped and a loaded body settles to its static state.
inline void damp_grid_motion(GridFields& g, double zeta, double kick) {
  const std::size_t nodes = g.mass.size();
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < nodes; ++i) {
    if (g.mass[i] > 0.0) {
      const Vec2 before = g.momentum[i] / g.mass[i];
      g.acceleration[i] -= zeta * before;
      g.velocity[i] -= kick * zeta * before;
    }
  }
}

// The damping forces' power over the step, -sum zeta m_g v_g . v_g^L, with
// v_g^L the velocity after every grid stage, over the components that move
// freely: a component a constraint prescribes (`fixed`, two flags per node)
// moves as prescribed whatever force acts on it, and ghost nodes beyond the
// walls only mirror the nodes inside.
inline double damping_power(const GridGeometry& grid, const GridFields& g, double zeta,
                            const std::vector<unsigned char>& fixed) {
  const int nx = grid.nodes_x(), ny = grid.nodes_y(), ghost = grid.ghost_layers;
  ThreadOrderedSums<1> power;
#pragma omp parallel
  {
    double own = 0.0;
#pragma omp for schedule(static)
    for (int j = ghost; j < ny - ghost; ++j)
      for (int i = ghost; i < nx - ghost; ++i) {
        const std::size_t node = std::size_t(grid.node(i, j));
        if (!(g.mass[node] > 0.0)) continue;
        for (int a = 0; a < 2; ++a)
          if (!fixed[2 * node + std::size_t(a)]) own -= zeta * g.momentum[node][a] * g.velocity[node][a];
      }
    power.keep({own});
  }
  return power.total()[0];
}

// ---------------------------------------------------------------- what a scene adds

// The optional stages of a scene's step; what it leaves empty is absent.
struct SceneStages {
  std::shared_ptr<BodyForce> body_force;    // a body force per unit mass
  // Tractions on the sides of the boundary particles' domains (traction.hpp).
  std::shared_ptr<BoundaryTraction> traction;
  std::vector<NodeConstraint> constraints;  // prescribed motion of grid nodes
  // Points where the grid motion, read with the method's grid basis, is held
  // at rest (rest_points.hpp): a boundary the nodes do not lie on.
  std::vector<Vec2> rest_points;
  double damping = 0.0;                     // zeta of eq. 1.65 [1/s]; 0: no damping
  std::optional<RigidBody> contact;         // a rigid master in frictionless contact (contact.hpp)
  // Two deformable bodies in frictionless contact on the grid: particles
  // [0, second_body) are the first, [second_body, n) the second, each with its
  // own grid velocity field (contact.hpp). 0: one body.
  std::size_t second_body = 0;
  // Two materials in one body (soft against stiff, PROBLEMS.md section 6):
  // particles [0, second_material_from) take the run's material,
  // [second_material_from, n) this one, a model of the same kind with its own
  // constants. Absent: one material.
  std::optional<MaterialModel> second_material;
  std::size_t second_material_from = 0;
};

}  // namespace mpmvv
