#include "settling.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mpmvv::app {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The slowest decay rate of a mode of eq. 1.65 with omega >= omega_1.
double slowest_decay(double omega, double zeta) {
  const double half = 0.5 * zeta;
  return half - std::sqrt(std::max(0.0, half * half - omega * omega));
}

}  // namespace

SettlingWatch::SettlingWatch(const SettlingBody& body, double end_time, bool relaxes)
    : body_(body),
      relaxes_(relaxes),
      decay_rate_(relaxes ? slowest_decay(body.lowest_angular_frequency, body.damping) : 0.0),
      from_(decay_rate_ > 0.0 ? end_time - 1.0 / decay_rate_ : kNaN),
      kept_at_(kNaN) {}

bool SettlingWatch::observe(double t, const Particles& P) {
  if (!relaxes_ || !position_.empty() || !(t >= from_)) return false;
  kept_at_ = t;
  position_ = P.position;
  deformation_gradient_ = P.deformation_gradient;
  return true;
}

Settling SettlingWatch::measure(double t, const Stepper& stepper) const {
  return relaxes_ ? relaxation(t, stepper.model().particles) : stepper.distance_to_equilibrium(body_.shear_modulus);
}

Settling SettlingWatch::relaxation(double t, const Particles& P) const {
  const double elapsed = t - kept_at_;
  if (position_.size() != P.size() || !(elapsed > 0.0)) return {};
  // Reference-volume-weighted RMS over the particles of the motion since, and
  // of the symmetric part of F's change (the small strain it made).
  double moved = 0.0, strained = 0.0, volume = 0.0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    const double w = P.reference_volume[p];
    const Mat2 dF = P.deformation_gradient[p] - deformation_gradient_[p];
    moved += w * (P.position[p] - position_[p]).squaredNorm();
    strained += w * (0.5 * (dF + dF.transpose())).squaredNorm();
    volume += w;
  }
  if (!(volume > 0.0)) return {};
  // What a motion decaying as exp(-s t) still has to go after moving this much
  // over `elapsed`.
  const double still = 1.0 / std::expm1(decay_rate_ * elapsed);
  return {still * std::sqrt(moved / volume), still * std::sqrt(strained / volume)};
}

}  // namespace mpmvv::app
