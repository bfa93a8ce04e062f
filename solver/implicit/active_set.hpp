// The nodes of the implicit static step that touch a rigid master
// (contact.hpp), found by an active-set iteration: each solve takes the
// nodes in contact as holding their normal displacement to the master's
// (unknowns.hpp); after it, a node whose contact force pulls leaves the set
// and a node that would cross the master joins, and the step is solved again
// until the set stays as it is (static_stepper.cpp).
#pragma once

#include <cmath>
#include <cstddef>
#include <optional>
#include <vector>

#include "unknowns.hpp"
#include "solver/contact.hpp"
#include "solver/grid.hpp"
#include "solver/particles.hpp"

namespace mpmvv {

class ActiveContactSet {
 public:
  explicit ActiveContactSet(std::optional<RigidBody> master) : master_(std::move(master)) {}

  bool has_master() const { return master_.has_value(); }

  // The master's motion over the step from t to t + dt, and the gap of every
  // node to it at t; the set kept from the step before (empty at first).
  template <class Shape>
  void start_step(const Shape& shape, const Particles& P, const GridGeometry& grid, double t, double dt) {
    if (!master_) return;
    time_ = t;
    master_step_ = master_->displacement(t + dt) - master_->displacement(t);
    ContactScratch scratch;
    node_contact_gaps(*master_, shape, P, grid, t, 3.0 * grid.h + master_step_.norm(), scratch);
    gap_ = scratch.node_gap;
    if (active_.size() != grid.node_count()) active_.assign(grid.node_count(), 0);
  }

  ContactUnknowns unknowns() const { return {master_ ? &*master_ : nullptr, active_, gap_, master_step_}; }

  // After a solve, given its node forces -(f_int - f_ext) and displacements u:
  // nodes whose contact force pulls are released, nodes that would cross the
  // master join. Returns whether the set changed.
  bool update(const GridGeometry& grid, const GridFields& fields, const std::vector<Vec2>& u) {
    if (!master_) return false;
    bool changed = false;
    for (int j = wall_node_y(grid, 0); j <= wall_node_y(grid, 1); ++j)
      for (int i = wall_node_x(grid, 0); i <= wall_node_x(grid, 1); ++i) {
        const std::size_t node = std::size_t(grid.node(i, j));
        if (!(fields.mass[node] > 0.0) || !std::isfinite(gap_[node])) continue;
        const Vec2 n = master_->normal(grid.node_position(i, j), time_);
        if (active_[node]) {
          // The master's push on the body, -(f_ext - f_int) along n, must be positive.
          if (-fields.force[node].dot(n) < 0.0) {
            active_[node] = 0;
            changed = true;
          }
        } else if ((u[node] - master_step_).dot(n) < -gap_[node] - 1e-12 * grid.h) {
          active_[node] = 1;
          changed = true;
        }
      }
    return changed;
  }

  const std::vector<unsigned char>& active() const { return active_; }

 private:
  std::optional<RigidBody> master_;
  double time_ = 0.0;  // the start of the step
  Vec2 master_step_ = Vec2::Zero();
  std::vector<double> gap_;
  std::vector<unsigned char> active_;
};

}  // namespace mpmvv
