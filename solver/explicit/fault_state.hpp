// The explicit step's injected fault (faults.hpp) and what it holds between
// stages: each stage asks once whether its fault is on, and a real run (no
// fault) holds nothing.
#pragma once

#include <algorithm>
#include <limits>
#include <string_view>
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
  // The factor on the shape gradients: cpdi-gradient's on CPDI's corner
  // gradients, linear-gradient's and gimp-gradient's on the hats' and uGIMP's
  // (each shape takes the factor of its own fault, `name` its Shape::name);
  // 1 otherwise.
  double gradient_scale(const char* name) const {
    if (is(SolverFault::cpdi_gradient)) return kFaultyCpdiGradientScale;
    const std::string_view shape = name;
    if (is(SolverFault::linear_gradient) && shape == "linear") return kFaultyGridGradientScale;
    if (is(SolverFault::gimp_gradient) && shape == "gimp") return kFaultyGridGradientScale;
    return 1.0;
  }
  // cpdi-shear-sign's sign on the cross terms of s^-T; 1 otherwise.
  double shear_sign() const { return is(SolverFault::cpdi_shear_sign) ? -1.0 : 1.0; }

  // Around a transfer that updates F and V: deformation-transpose applies the
  // update's increment transposed, frozen-volume keeps V_p0.
  void before_deformation(const Particles& P) {
    if (is(SolverFault::deformation_transpose)) held_deformation_ = P.deformation_gradient;
  }
  void after_deformation(Particles& P) const {
    if (is(SolverFault::deformation_transpose)) transpose_deformation_increments(P, held_deformation_);
    if (is(SolverFault::frozen_volume)) P.volume = P.reference_volume;
  }
  // Around the constitutive update: non-objective-stress forms the stress
  // from the symmetric part of F and puts F back after.
  void before_constitutive_update(Particles& P) {
    if (is(SolverFault::non_objective_stress)) symmetric_deformation(P, held_true_deformation_);
  }
  // After the constitutive update: kirchhoff-stress, no-hoop-stress.
  void after_constitutive_update(Particles& P) {
    if (is(SolverFault::non_objective_stress)) P.deformation_gradient.swap(held_true_deformation_);
    if (is(SolverFault::kirchhoff_stress)) stress_times_dilatation(P);
    if (is(SolverFault::no_hoop_stress)) std::fill(P.hoop_stress.begin(), P.hoop_stress.end(), 0.0);
  }
  // lagged-stress, after the whole stress update: the stress just updated is
  // held back for one step, and the forces of the next step weigh the one
  // before it.
  // A split (split.hpp) may have changed the particle count since the stress
  // was held: the particles new since then hold their current stress (a
  // split's halves keep their parent's, and a half that keeps the parent's
  // index its held one).
  void after_stress_update(Particles& P) {
    if (!is(SolverFault::lagged_stress)) return;
    const std::size_t held = held_stress_.size();
    if (held != P.stress.size()) {
      held_stress_.resize(P.stress.size());
      for (std::size_t p = held; p < P.stress.size(); ++p) held_stress_[p] = P.stress[p];
    }
    P.stress.swap(held_stress_);
  }
  // apic-transpose, after a velocity update that forms C_p.
  void after_velocity_update(Particles& P) const {
    if (is(SolverFault::apic_transpose)) transpose_affine_velocities(P);
  }
  // traction-factor, after the tractions' evaluation.
  void after_traction(std::vector<Vec2>& force) const {
    if (is(SolverFault::traction_factor))
      for (Vec2& f : force) f *= kFaultyTractionScale;
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
  std::vector<Mat2> held_true_deformation_;  // non-objective-stress: F while the stress reads sym F
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
