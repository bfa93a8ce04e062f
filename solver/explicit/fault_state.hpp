// The explicit step's injected fault (faults.hpp) and what it holds between
// stages: each stage asks once whether its fault is on, and a real run (no
// fault) holds nothing.
#pragma once

#include <algorithm>
#include <limits>
#include <vector>

#include "../model.hpp"
#include "../faults.hpp"
#include "../io/state_archive.hpp"
#include "../particles.hpp"
#include "../stages.hpp"

namespace mpmvv {

class FaultState {
 public:
  FaultState(SolverFault fault, const Particles& P) : fault_(fault) {
    if (fault_ == SolverFault::lagged_stress) held_stress_ = P.stress;
  }

  bool is(SolverFault f) const { return fault_ == f; }
  // cpdi-gradient's factor on the CPDI corner gradients; 1 otherwise.
  double gradient_scale() const { return is(SolverFault::cpdi_gradient) ? kFaultyCpdiGradientScale : 1.0; }

  // Around a transfer that updates F and V: deformation-transpose applies the
  // update's increment transposed, frozen-volume keeps V_p0.
  void before_deformation(const Particles& P) {
    if (is(SolverFault::deformation_transpose)) held_deformation_ = P.deformation_gradient;
  }
  void after_deformation(Particles& P) const {
    if (is(SolverFault::deformation_transpose)) transpose_deformation_increments(P, held_deformation_);
    if (is(SolverFault::frozen_volume)) P.volume = P.reference_volume;
  }
  // After the constitutive update: kirchhoff-stress, no-hoop-stress.
  void after_constitutive_update(Particles& P) const {
    if (is(SolverFault::kirchhoff_stress)) stress_times_dilatation(P);
    if (is(SolverFault::no_hoop_stress)) std::fill(P.hoop_stress.begin(), P.hoop_stress.end(), 0.0);
  }
  // lagged-stress, after the whole stress update: the stress just updated is
  // held back for one step, and the forces of the next step weigh the one
  // before it.
  void after_stress_update(Particles& P) {
    if (is(SolverFault::lagged_stress)) P.stress.swap(held_stress_);
  }
  // The time the body force is read at for a step from t: under
  // lagged-force-time the time of the evaluation before.
  double force_time(double t) {
    if (!is(SolverFault::lagged_force_time)) return t;
    const double earlier = std::min(t, force_time_);
    force_time_ = t;
    return earlier;
  }
  // force-at-current-position: the force's points placed at x_p for this
  // evaluation (and back).
  void before_force(BodyForce& force, Particles& P) const {
    if (!is(SolverFault::force_at_current_position)) return;
    P.reference_position.swap(P.position);
    force.prepare(P);
    P.reference_position.swap(P.position);
  }
  // frozen-time-step: the signal speed of the first scan, kept.
  ParticleScan scanned(ParticleScan s) const {
    if (!is(SolverFault::frozen_time_step)) return s;
    if (!(first_signal_speed_ > 0.0)) first_signal_speed_ = s.max_signal_speed;
    s.max_signal_speed = first_signal_speed_;
    return s;
  }

  void persist(StateArchive& a) {
    a.field("held_deformation", held_deformation_);
    a.field("held_stress", held_stress_);
    a.field("force_time", force_time_);
    a.field("first_signal_speed", first_signal_speed_);
  }

 private:
  SolverFault fault_;  // none, but in a fault-injection test
  // F before an update (deformation-transpose), the stress one update behind
  // (lagged-stress), the time of the last force evaluation
  // (lagged-force-time) and the first scan's signal speed (frozen-time-step).
  std::vector<Mat2> held_deformation_;
  std::vector<Mat2> held_stress_;
  double force_time_ = std::numeric_limits<double>::infinity();
  mutable double first_signal_speed_ = 0.0;
};

// consistent-mass: m_g = sum_p m_p S_gp^2 over the particles of `range`.
template <class Shape>
void lump_consistent_diagonal(const Shape& shape, const Particles& P, GridFields& g, ParticleRange range) {
  std::fill(g.mass.begin(), g.mass.end(), 0.0);
  Stencil<Shape::stencil_size> st;
  for (std::size_t p = range.first; p < range.end(P); ++p) {
    shape.evaluate(p, st);
    for (int k = 0; k < st.count; ++k) g.mass[st.node[k]] += P.mass[p] * st.weight[k] * st.weight[k];
  }
}

}  // namespace mpmvv
