// How far a run that settles to a static state (a load ramped slowly, then
// held: scenes/quasi_static.hpp) still is from it at its end, written to
// the results file as the measurements settling_displacement and
// settling_strain, which the report and the gate compare errors with
// (reports/scales.py: settling_scale). An error no larger than what the
// solver's stopping short of the static state leaves measures the stopping
// point, not the method.
//
// Implicit load steps each end in equilibrium up to a Newton tolerance: the
// stepper gives the correction one more iteration would make
// (Stepper::distance_to_equilibrium). Dynamic relaxation has no tolerance: it
// approaches the static state as its slowest mode decays, at the rate s of the
// damped lowest mode (eq. 1.65: u'' + zeta u' + omega_1^2 u = 0, s = zeta / 2
// - sqrt(max(0, zeta^2 / 4 - omega_1^2)); a faster mode decays at least as
// fast). Over the run's last interval of 1 / s the particles move by d; a
// motion that decays as exp(-s t) has d (e - 1)^-1 = 0.58 d still to go, the
// estimate written. The same holds for each error norm the scene reads at the
// end: its change over the interval, extrapolated alike, is how much it would
// still change (/settling in the results file), where the particles' motion
// may be noise that a mean over a region averages away. It is measured, not
// bounded: a mode that decays more slowly than the lowest's (a nonlinear body
// far from its small-strain frequency, a coarse mesh whose lowest mode lies
// below the body's) moves less over the interval than it has still to go.
#pragma once

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "solver/stepper.hpp"
#include "solver/particles.hpp"

namespace mpmvv::app {

struct SettlingBody {
  double lowest_angular_frequency;  // omega_1 [rad/s]
  double shear_modulus;             // mu, small-strain [Pa]
  double damping;                   // zeta of eq. 1.65 [1/s] (dynamic relaxation)
};

class SettlingWatch {
 public:
  // For a run to `end_time`; `relaxes`: the stepper settles in time (explicit).
  SettlingWatch(const SettlingBody& body, double end_time, bool relaxes);

  // Keeps the particles' state the first time t reaches the start of the
  // last interval of 1 / s (t = 0: the initial state); true when it did now.
  bool observe(double t, const Particles& P);
  // The error norms (name, value) at the time observe() kept the state.
  void keep_norms(std::vector<std::pair<std::string, double>> norms) { norms_ = std::move(norms); }
  // For each kept norm whose value at the end, time t, `at_end` gives (NaN:
  // none), what it would still change: |E(t) - E(kept)| / (exp(s (t - kept)) - 1).
  template <class AtEnd>
  std::vector<std::pair<std::string, double>> norm_settling(double t, const AtEnd& at_end) const;
  // At the end of the run, at time t.
  Settling measure(double t, const Stepper& stepper) const;
  bool relaxes() const { return relaxes_; }
  double decay_rate() const { return decay_rate_; }
  double kept_at() const { return kept_at_; }
  // What the relaxation still has to go, from the particles at time t and the
  // state observe() kept.
  Settling relaxation(double t, const Particles& P) const;

  // What observe() kept (the rest follows from the constructor's arguments).
  template <class Archive>
  void persist(Archive& a) {
    a.field("kept_at", kept_at_);
    a.field("norms", norms_);
    a.field("position", position_);
    a.field("deformation_gradient", deformation_gradient_);
  }

 private:
  SettlingBody body_;
  bool relaxes_;
  double decay_rate_;   // s [1/s]; 0: no damping, the run never settles
  double from_;         // end_time - 1 / s
  double kept_at_;
  std::vector<std::pair<std::string, double>> norms_;
  std::vector<Vec2> position_;
  std::vector<Mat2> deformation_gradient_;
};

template <class AtEnd>
std::vector<std::pair<std::string, double>> SettlingWatch::norm_settling(double t, const AtEnd& at_end) const {
  std::vector<std::pair<std::string, double>> out;
  const double elapsed = t - kept_at_;
  if (!relaxes_ || !(elapsed > 0.0)) return out;
  for (const auto& [name, kept] : norms_) {
    const double end = at_end(name);
    if (std::isfinite(end) && std::isfinite(kept))
      out.push_back({name, std::abs(end - kept) / std::expm1(decay_rate_ * elapsed)});
  }
  return out;
}

}  // namespace mpmvv::app
