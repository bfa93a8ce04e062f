#include "monitor_log.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "solver/io/state_archive.hpp"

namespace mpmvv::app {

void MonitorLog::start(const Stepper& s) {
  const Monitors m = s.monitors();
  initial_energy_ = m.kinetic + m.strain;
  largest_energy_ = initial_energy_;
  rows_.clear();
  sampled_motion_ = 0.0;
  stop_ = {};
}

void MonitorLog::record(double t, const Stepper& s, int stable_step_iterations, double rule_step, double blowup_factor) {
  const Monitors m = s.monitors();
  const EnergyLedger& w = s.ledger();
  const double energy = m.kinetic + m.strain;
  const double created = energy - initial_energy_ - w.total();
  // The scale: the energy at the start and the largest work yet done on the
  // run by any one agent (not the energy now, which a blow-up inflates).
  largest_energy_ = std::max({largest_energy_, std::abs(w.body), std::abs(w.constraints), std::abs(w.contact),
                              std::abs(w.damping)});
  double frequency = std::numeric_limits<double>::quiet_NaN(), cfl_step = frequency;
  if (stable_step_iterations > 0) {
    frequency = s.largest_frequency(stable_step_iterations);
    cfl_step = rule_step;
  }
  // The exact motion's angular momentum: with the errors at this output
  // time, which evaluate the exact state of every particle (at_output).
  const double exact_spin = std::numeric_limits<double>::quiet_NaN();
  rows_.push_back({t, m, w, created, frequency, cfl_step, exact_spin, largest_energy_, m.min_J, m.max_J,
                   Vec2::Constant(std::numeric_limits<double>::quiet_NaN())});
  if (created > blowup_factor * largest_energy_ && created > 0.0)
    stop_ = {"energy blow-up",
             fmt::format("at t = {:.6g} s the run made {:.4g} J of energy from nothing, {:.3g} times the {:.4g} J it "
                         "started with or was given (energy_blowup_factor = {})",
                         t, created, created / largest_energy_, largest_energy_, blowup_factor)};
}

JRatioRange j_ratio_range(const std::vector<double>& ratio, const std::vector<Vec2>& reference_position) {
  JRatioRange range{std::numeric_limits<double>::infinity(), 0.0,
                    Vec2::Constant(std::numeric_limits<double>::quiet_NaN())};
  double farthest = -1.0;
  bool not_a_number = false;
  for (std::size_t p = 0; p < ratio.size(); ++p) {
    const double r = ratio[p];
    const double distance = r > 0.0 ? std::abs(std::log(r)) : std::numeric_limits<double>::infinity();
    if (!(distance <= farthest)) {  // NaN is farther than anything
      farthest = distance;
      range.worst_reference = reference_position[p];
    }
    not_a_number = not_a_number || std::isnan(r);
    range.min = std::min(range.min, r);
    range.max = std::max(range.max, r);
  }
  if (not_a_number) range.min = range.max = std::numeric_limits<double>::quiet_NaN();
  return range;
}

void MonitorLog::record_J_ratio(const Particles& P) {
  Row& row = rows_.back();
  const JRatioRange range = j_ratio_range(j_ratio_, P.reference_position);
  row.min_J_ratio = range.min;
  row.max_J_ratio = range.max;
  if (!j_ratio_.empty()) row.worst_J_reference = range.worst_reference;
}

double sampled_exact_motion(double t, const Particles& P, const mms::ExactSolution& solution) {
  const std::size_t n = P.size(), stride = std::max<std::size_t>(1, n / 256);
  double weight = 0.0, exact2 = 0.0;
  for (std::size_t p = 0; p < n; p += stride) {
    const Vec2 X = P.reference_position[p];
    weight += P.reference_volume[p];
    exact2 += P.reference_volume[p] * (solution.position(X, t) - X).squaredNorm();
  }
  return weight > 0.0 ? std::sqrt(exact2 / weight) : 0.0;
}

void MonitorLog::sample_motion(double t, const Particles& P, const mms::ExactSolution& solution) {
  sampled_motion_ = std::max(sampled_motion_, sampled_exact_motion(t, P, solution));
}

RunHealth MonitorLog::health(const ErrorTable& errors, const HealthRules& rules) const {
  std::vector<HealthSample> samples;
  for (const Row& r : rows_)
    samples.push_back({r.time, r.min_J_ratio, r.max_J_ratio, r.worst_J_reference, r.created, r.energy_scale});
  return judge_health(samples, errors, rules, sampled_motion_);
}

void MonitorLog::persist(StateArchive& a) {
  a.field("monitor_rows", rows_);
  a.field("j_ratio", j_ratio_);
  a.field("sampled_motion", sampled_motion_);
  a.field("initial_energy", initial_energy_);
  a.field("largest_energy", largest_energy_);
  a.field("stop", stop_);
}

}  // namespace mpmvv::app
