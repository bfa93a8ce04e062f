// What the scene does to the grid's motion in an explicit step, after the
// node sums: its damping (eq. 1.65), the walls, its prescribed node motion
// (boundary.hpp), its rest points (rest_points.hpp) and its rigid contact
// master (contact.hpp), with the work each does booked where the stepper
// keeps it.
#pragma once

#include <algorithm>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "../boundary.hpp"
#include "../contact.hpp"
#include "../monitors.hpp"
#include "../rest_points.hpp"
#include "../stages.hpp"

namespace mpmvv {

// The stepper's books (stepper.hpp) the conditions write.
struct GridBooks {
  EnergyLedger& ledger;
  std::vector<double>& reactions;  // each constraint's reaction in the last step
  ContactForces& contact_forces;   // the contact force of the last step at each node
};

// The nodal mass at or below which a node is empty for the grid update: the
// shape's unresolved share of a particle's mass (its `unresolved_mass`
// trait; none for most shapes) times the smallest particle mass. Where a
// domain's side lies on a grid line to round-off, exact CPDI (cpdi_exact.hpp)
// gives the node beyond it a sliver of width e cells: its mass goes as e^2,
// the forces on it (the stress against a boundary traction) as e, and they
// balance only to the round-off of their own size, so that under USL
// v_g^L = v_g + dt f_g / m_g grows as 1 / e: 1e5 m/s^2 at e = 1e-16 in the
// traction patch test, and the particles beside the line lose their F in a
// few steps (suites/patch-tests.toml). Such a node carries nothing the
// transfers can resolve.
template <class Shape>
double unresolved_node_mass(const Particles& P) {
  double share = 0.0;
  if constexpr (requires { Shape::unresolved_mass; }) share = Shape::unresolved_mass;
  if (share == 0.0 || P.mass.empty()) return 0.0;
  return share * *std::min_element(P.mass.begin(), P.mass.end());
}

template <class Shape>
class GridConditions {
 public:
  // Takes the constraints and the contact master out of `stages`.
  GridConditions(const GridGeometry& grid, const Particles& P, SceneStages& stages, SolverFault fault)
      : swapped_walls_(fault == SolverFault::swapped_walls),
        mirrored_wall_(fault == SolverFault::mirrored_wall),
        unresolved_mass_(unresolved_node_mass<Shape>(P)),
        constraints_(std::move(stages.constraints)),
        rest_(stages.rest_points.empty()
                  ? std::nullopt
                  : std::optional<RestPoints>(std::in_place,
                        basis_rows<typename Shape::GridBasis>(grid, stages.rest_points),
                        prescribed_components(grid.node_count(), constraints_))),
        damping_(stages.damping),
        contact_(std::move(stages.contact)) {
    if (damping_ > 0.0) fixed_components_ = prescribed_components(grid.node_count(), constraints_);
  }

  // The walls (stages.hpp), or under swapped-walls the tangential component
  // held, under mirrored-wall the normal one reflected.
  void walls(const GridGeometry& grid, GridFields& g) const { apply_walls(grid, g, swapped_walls_, mirrored_wall_); }

  // After a velocity-only map (USF, MUSL): the walls, the prescribed node
  // motion and the rest points on the grid velocity. (Those passes see
  // contact through the particle velocities it has corrected.)
  void on_velocity(const GridGeometry& grid, GridFields& g, double t, double dt, double kick) {
    walls(grid, g);
    if (!constraints_.empty()) apply_constraints(constraints_, t, dt, kick, g);
    if (rest_) rest_->apply(g, kick);
  }

  // a_g and v_g^L from the node sums (eqs. 1.71-1.72), with the damping, then
  // the walls, the prescribed node motion, the rest points and the contact.
  void advance(const Shape& shape, const Particles& P, const GridGeometry& grid, GridFields& g, double t,
               double dt, double kick, GridBooks books) {
    update_grid_motion(g, kick, unresolved_mass_);
    if (damping_ > 0.0) damp_grid_motion(g, damping_, kick);
    walls(grid, g);
    if (!constraints_.empty()) {
      books.reactions = apply_constraints(constraints_, t, dt, kick, g);
      book_constraint_work(t, dt, books);
    }
    if (rest_) rest_->apply(g, kick);
    if (contact_) {
      apply_rigid_contact(*contact_, shape, P, grid, g, t, dt, kick, contact_scratch_, books.contact_forces);
      const ContactForces& f = books.contact_forces;
      for (std::size_t i = 0; i < f.node_force.size(); ++i)
        if (f.node_force[i].x() != 0.0 || f.node_force[i].y() != 0.0)
          books.ledger.contact += dt * f.node_force[i].dot(g.velocity[i]);
    }
    if (damping_ > 0.0) books.ledger.damping += dt * damping_power(grid, g, damping_, fixed_components_);
  }

  // advance for two bodies in contact, each on its own field (no rest points,
  // no rigid master): each constraint's reaction is the sum over both.
  void advance_bodies(const GridGeometry& grid, GridFields& a, GridFields& b, double t, double dt, double kick,
                      GridBooks books) {
    std::vector<double> reactions(constraints_.size(), 0.0);
    for (GridFields* field : {&a, &b}) {
      update_grid_motion(*field, kick, unresolved_mass_);
      if (damping_ > 0.0) damp_grid_motion(*field, damping_, kick);
      walls(grid, *field);
      if (!constraints_.empty()) {
        const std::vector<double> r = apply_constraints(constraints_, t, dt, kick, *field);
        for (std::size_t k = 0; k < r.size(); ++k) reactions[k] += r[k];
      }
      if (damping_ > 0.0) books.ledger.damping += dt * damping_power(grid, *field, damping_, fixed_components_);
    }
    books.reactions = reactions;
    if (!constraints_.empty()) book_constraint_work(t, dt, books);
  }

 private:
  // Each constraint's reaction does work along its prescribed increment.
  void book_constraint_work(double t, double dt, GridBooks books) const {
    for (std::size_t k = 0; k < constraints_.size(); ++k)
      books.ledger.constraints +=
          books.reactions[k] * (constraints_[k].displacement(t + dt) - constraints_[k].displacement(t));
  }

  bool swapped_walls_;  // the swapped-walls fault (faults.hpp)
  bool mirrored_wall_;  // the mirrored-wall fault (faults.hpp)
  double unresolved_mass_;  // [kg] a node's mass at or below this is empty (unresolved_node_mass)
  std::vector<NodeConstraint> constraints_;
  std::optional<RestPoints> rest_;  // absent without rest points
  double damping_;                  // zeta [1/s]; 0: none
  std::vector<unsigned char> fixed_components_;  // with damping: the components constraints prescribe
  std::optional<RigidBody> contact_;
  ContactScratch contact_scratch_;
};

}  // namespace mpmvv
