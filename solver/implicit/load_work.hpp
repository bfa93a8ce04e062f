// The work of the loads over an implicit static step (energy ledger,
// monitors.hpp), by the trapezoid rule between the loads at the step's start
// and at its end, with the node displacements u of the step: the node
// constraints' reactions along their increments, the body force along the
// particles' displacements, and a rigid master's contact forces along the
// nodes' displacements.
#pragma once

#include <cstddef>
#include <vector>

#include "solver/boundary.hpp"
#include "solver/contact.hpp"
#include "solver/grid.hpp"
#include "solver/monitors.hpp"
#include "solver/particles.hpp"
#include "solver/shape/stencil.hpp"

namespace mpmvv {

// Each constraint's reaction at the step's end, the negated node sums along
// its axis at equilibrium (`reactions` holds those of the step's start).
inline void book_constraint_work(const std::vector<NodeConstraint>& constraints, const GridFields& g, double t,
                                 double dt, std::vector<double>& reactions, EnergyLedger& ledger) {
  const std::vector<double> previous = reactions;
  reactions.clear();
  for (std::size_t k = 0; k < constraints.size(); ++k) {
    const NodeConstraint& c = constraints[k];
    double reaction = 0.0;
    for (std::size_t node : c.nodes) reaction -= g.force[node][c.axis];
    reactions.push_back(reaction);
    const double before = k < previous.size() ? previous[k] : 0.0;
    ledger.constraints += 0.5 * (before + reaction) * (c.displacement(t + dt) - c.displacement(t));
  }
}

// `previous`: the body force of the step's start (empty at the first step),
// replaced by the particles' of its end.
template <class Shape>
void book_body_force_work(const Shape& shape, const Particles& P, const std::vector<Vec2>& u,
                          std::vector<Vec2>& previous, EnergyLedger& ledger) {
  double work = 0.0;
  Stencil<Shape::stencil_size> s;
  for (std::size_t p = 0; p < P.size(); ++p) {
    shape.evaluate(p, s);
    Vec2 move = Vec2::Zero();
    for (int k = 0; k < s.count; ++k) move += s.weight[k] * u[std::size_t(s.node[k])];
    const Vec2 before = previous.empty() ? Vec2::Zero() : previous[p];
    work += P.mass[p] * 0.5 * (before + P.body_force[p]).dot(move);
  }
  ledger.body += work;
  previous = P.body_force;
}

// The contact force at the step's end is what holds the nodes in contact
// (`active`) in equilibrium, -(node sums); `forces` holds those of its start.
inline void book_contact_work(const std::vector<unsigned char>& active, const GridFields& g,
                              const std::vector<Vec2>& u, ContactForces& forces, EnergyLedger& ledger) {
  const std::vector<Vec2> previous = forces.node_force;
  forces.node_force.assign(g.force.size(), Vec2::Zero());
  forces.total.setZero();
  for (std::size_t i = 0; i < active.size(); ++i)
    if (active[i] && g.mass[i] > 0.0) {
      forces.node_force[i] = -g.force[i];
      forces.total += forces.node_force[i];
    }
  for (std::size_t i = 0; i < forces.node_force.size(); ++i) {
    const Vec2 before = i < previous.size() ? previous[i] : Vec2::Zero();
    ledger.contact += 0.5 * (before + forces.node_force[i]).dot(u[i]);
  }
}

}  // namespace mpmvv
