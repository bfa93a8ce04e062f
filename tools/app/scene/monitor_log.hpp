// The run's health as it goes: the monitors at every output time
// (solver/monitors.hpp), the energy balance and its blow-up stop, the range
// of J_p / J_exact, and the exact motion sampled after every step; the health
// verdict is judged from them (health.hpp).
#pragma once

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "mms/exact_solution.hpp"
#include "solver/monitors.hpp"
#include "solver/stepper.hpp"
#include "tools/app/scene/health.hpp"

namespace mpmvv::app {

// The range of J_p / J_exact over particles whose ratios are `ratio` (NaN
// when any is), and the reference position of the particle farthest from 1
// in ratio (a NaN counts as farthest of all).
struct JRatioRange {
  double min, max;
  Vec2 worst_reference;
};
JRatioRange j_ratio_range(const std::vector<double>& ratio, const std::vector<Vec2>& reference_position);

// The RMS exact displacement at t over every k-th particle (about 256 of
// them, weighted by reference volume); 0 without particles.
double sampled_exact_motion(double t, const Particles& P, const mms::ExactSolution& solution);

class MonitorLog {
 public:
  struct Row {
    double time;
    Monitors monitors;
    EnergyLedger work;
    double created;
    double largest_frequency, cfl_step;  // with stable_step_iterations > 0
    double exact_angular_momentum;       // NaN without an exact motion (or in r-z)
    double energy_scale;                 // the balance's scale at this time (record)
    // The range of J_p / J_exact(X_p, t) over the particles (J_exact = 1
    // without an exact motion), and the reference position of the particle
    // farthest from 1 in ratio (RunHealth).
    double min_J_ratio, max_J_ratio;
    Vec2 worst_J_reference;
  };

  // The energy at the start, for the balance; forgets what was recorded.
  void start(const Stepper& s);

  // Monitors at output time t, and the energy balance: what the run made from
  // nothing, E - E_0 - W (W the work done on it), against the larger of the
  // energy it started with and the largest work done on it so far; a stop
  // (stop()) when it made more than `blowup_factor` times that.
  // `stable_step_iterations` > 0: the power iteration's largest frequency
  // beside `rule_step`, the time-step rule's last step.
  void record(double t, const Stepper& s, int stable_step_iterations, double rule_step, double blowup_factor);

  // J_p / J_exact of each particle at the last output time (norms.hpp:
  // field_errors fills it), and its range into that time's row.
  std::vector<double>& j_ratio() { return j_ratio_; }
  void record_J_ratio(const Particles& P);
  void set_exact_angular_momentum(double spin) { rows_.back().exact_angular_momentum = spin; }

  // The RMS exact displacement over every k-th particle (about 256 of them,
  // weighted by reference volume), after every step: the health verdict's
  // measure of the whole motion between the output times (health.hpp).
  void sample_motion(double t, const Particles& P, const mms::ExactSolution& solution);

  RunHealth health(const ErrorTable& errors, const HealthRules& rules) const;
  const std::pair<std::string, std::string>& stop() const { return stop_; }

  const std::vector<Row>& rows() const { return rows_; }
  double initial_energy() const { return initial_energy_; }
  double energy_scale() const { return largest_energy_; }

  // What has been recorded, under its restart-file names.
  void persist(StateArchive& a);

 private:
  std::vector<Row> rows_;
  std::vector<double> j_ratio_;  // J_p / J_exact at the last output time (exact motion only)
  double sampled_motion_ = 0.0;  // the largest RMS exact displacement sampled after a step (sample_motion)
  double initial_energy_ = 0.0, largest_energy_ = 0.0;
  std::pair<std::string, std::string> stop_;
};

}  // namespace mpmvv::app
