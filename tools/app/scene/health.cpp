#include "health.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "scene.hpp"

namespace mpmvv::app {

namespace {

// A norm relative to the exact signal (the time-integrated one, the scenes'
// error_* columns) is 0 / 0 where that signal is zero (the ring's cosine
// motion at t = 0 and 1 s): not a number without anything lost. Every
// absolute norm of a state that became NaN is NaN.
bool relative_norm(const std::string& name) {
  return name.rfind("error_", 0) == 0 || name == "particle_relative_L2_integrated";
}

}  // namespace

RunHealth judge_health(const std::vector<HealthSample>& samples, const ErrorTable& errors, const HealthRules& rules,
                       double motion_between_outputs) {
  const std::vector<double>* error = errors.find("particle_L2");
  const std::vector<double>* exact = errors.find("exact_displacement_L2");
  // The whole motion: the largest RMS exact displacement at any time sampled.
  double motion = motion_between_outputs;
  if (exact)
    for (double u : *exact) motion = std::max(motion, u);
  const double f = rules.J_factor;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const HealthSample& s = samples[k];
    RunHealth h{true, "", s.time, std::nullopt};
    if (!(s.min_J_ratio >= 1.0 / f && s.max_J_ratio <= f)) {
      h.reason = fmt::format("J{} ranged over [{:.3g}, {:.3g}], outside [1/{:g}, {:g}] (health_J_factor)",
                             rules.exact_J ? " / J_exact" : " (J_exact taken as 1)", s.min_J_ratio, s.max_J_ratio, f,
                             f);
      if (s.worst_J_reference.allFinite()) h.reference_position = s.worst_J_reference;
      return h;
    }
    for (const auto& [name, values] : errors.columns)
      if (k < values.size() && std::isnan(values[k]) && !relative_norm(name)) {
        h.reason = fmt::format("the error norm {} is not a number", name);
        return h;
      }
    if (error && k < error->size() && motion > 0.0 && (*error)[k] > motion) {
      h.reason = fmt::format("the displacement error particle_L2 = {:.3g} m exceeds the largest RMS exact "
                             "displacement of the run, {:.3g} m (every step sampled)",
                             (*error)[k], motion);
      return h;
    }
    if (s.energy_created < 0.0 && -s.energy_created > rules.energy_loss_factor * s.energy_scale) {
      h.reason = fmt::format("the method lost {:.4g} J of energy, {:.3g} times the {:.4g} J the run started with or "
                             "was given (health_energy_loss_factor = {:g})",
                             -s.energy_created, -s.energy_created / s.energy_scale, s.energy_scale,
                             rules.energy_loss_factor);
      return h;
    }
  }
  return {};
}

}  // namespace mpmvv::app
