// The health verdict of a run, beside its status: whether it kept its
// solution. A run can reach its end time with the solution gone (J near zero
// in a layer of particles, an error larger than the whole motion); such a run
// is "lost", not "completed" (reports/results-format.md).
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "solver/tensor.hpp"

namespace mpmvv::app {

struct ErrorTable;

// The verdict: the first output time at which a rule fails, the rule with its
// numbers, and for J the reference position of the particle farthest off.
struct RunHealth {
  bool lost = false;
  std::string reason;
  double time = std::numeric_limits<double>::quiet_NaN();
  std::optional<Vec2> reference_position;
};

// What the rules read at one output time besides the error norms.
struct HealthSample {
  double time;
  // The range of J_p / J_exact(X_p, t) over the particles (NaN when any J is),
  // J_exact = 1 where the scene has no exact motion, and the reference
  // position of the particle farthest from 1 in ratio.
  double min_J_ratio, max_J_ratio;
  Vec2 worst_J_reference;
  // The energy balance (monitors.hpp): made (> 0) or lost (< 0) by the
  // method, and its scale, the larger of the starting energy and the largest
  // work done on the run.
  double energy_created, energy_scale;
};

struct HealthRules {
  double J_factor = 20.0;           // J / J_exact within [1 / J_factor, J_factor]
  double energy_loss_factor = 1.0;  // energy lost at most this times the scale
  bool exact_J = true;              // the samples' J_exact is the exact motion's (else taken as 1)
};

// The rules, checked in time order over the samples (one per output time, in
// the order of errors.time); at one time J's rule is named first, then an
// absolute error norm that is not a number (a relative one is 0 / 0 where the
// exact signal vanishes), then particle_L2 above the whole exact motion (when
// the run has that column), then the energy lost. The whole motion is the
// largest RMS exact displacement of the run: the larger of the
// exact_displacement_L2 column and `motion_between_outputs`, the same measure
// sampled between the output times (a vibration read at whole periods has
// none at its output times).
RunHealth judge_health(const std::vector<HealthSample>& samples, const ErrorTable& errors, const HealthRules& rules,
                       double motion_between_outputs = 0.0);

}  // namespace mpmvv::app
