#include "time_loop.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace mpmvv {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

const char* to_string(TimeIntegration t) {
  switch (t) {
    case TimeIntegration::symplectic_euler: return "symplectic-euler";
    case TimeIntegration::central_difference: return "central-difference";
  }
  return "?";
}

const char* to_string(TimeStepRule r) {
  switch (r) {
    case TimeStepRule::cfl: return "cfl";
    case TimeStepRule::stable: return "stable";
  }
  return "?";
}

std::atomic<bool>& stop_request() {
  static std::atomic<bool> requested{false};
  static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");
  return requested;
}

RunOutcome run_time_loop(Stepper& stepper, const TimeLoopOptions& options, RunObserver& observer,
                         const ProgressSink& progress, double progress_interval_seconds) {
  if (options.output_times.empty() || options.output_times.back() != options.end_time)
    throw std::invalid_argument("output times must end at the end time");

  RunOutcome out;
  const auto start = Clock::now();
  auto last_report = start;
  // (The particle count may grow: split.hpp.)
  auto n = [&] { return stepper.model().particles.size(); };
  const double h = stepper.model().grid.h;
  // A step this small means the signal speed has run away.
  const double smallest_step = 1e-12 * options.end_time;

  auto fail = [&](const ParticleScan& scan, double t) {
    const ParticleFault fault = stepper.diagnose(scan.first_unhealthy);
    out.failure_reason = fault.reason;
    out.failure_detail = fault.detail;
    out.failure_time = t;
    out.failure_step = out.steps;
    out.failure_particle = static_cast<long long>(scan.first_unhealthy);
  };

  observer.initial(stepper);
  double t = 0.0;
  double previous_dt = 0.0;
  std::size_t next_output = 0;
  ParticleScan scan = stepper.prepare_step(t);
  if (scan.first_unhealthy < n()) fail(scan, t);

  // TimeStepRule::stable: the last two measurements of omega_max, and the
  // estimate at time t: the last one, raised along their growth since.
  const bool stable_rule = options.step_rule == TimeStepRule::stable && options.fixed_step <= 0.0;
  double omega_last = 0.0, omega_before = 0.0, t_last = 0.0, t_before = 0.0;
  double signal_at_measurement = 0.0;
  long long steps_at_measurement = 0;
  // False when the measurement gives no frequency; at the start that is a
  // stepper without one (an implicit step), later a run to stop with its data.
  auto measure = [&] {
    omega_before = omega_last;
    t_before = t_last;
    omega_last = stepper.largest_frequency(options.track_iterations);
    t_last = t;
    signal_at_measurement = scan.max_signal_speed;
    steps_at_measurement = out.steps;
    ++out.frequency_measurements;
    const bool measured = omega_last > 0.0 && std::isfinite(omega_last);
    if (!measured && out.steps == 0)
      throw std::invalid_argument("the stable time-step rule needs a stepper that measures its largest frequency "
                                  "(an explicit step)");
    return measured;
  };
  auto omega_now = [&] {
    if (!(omega_before > 0.0 && t_last > t_before)) return omega_last;
    return omega_last + std::max(0.0, (omega_last - omega_before) / (t_last - t_before)) * (t - t_last);
  };

  while (out.failure_reason.empty() && next_output < options.output_times.size()) {
    if (stop_request().load(std::memory_order_relaxed)) {
      out.failure_reason = kInterrupted;
      out.failure_detail = "stopped on request (a signal) before step " + std::to_string(out.steps + 1);
      out.failure_time = t;
      out.failure_step = out.steps;
      break;
    }
    const bool due = out.steps == 0 || out.steps - steps_at_measurement >= options.track_every ||
                     scan.max_signal_speed > options.track_growth * signal_at_measurement;
    if (stable_rule && due && !measure()) {
      out.failure_reason = "stable step unmeasured";
      out.failure_detail = "the power iteration for omega_max gave " + std::to_string(omega_last) + " rad/s";
      out.failure_time = t;
      out.failure_step = out.steps;
      break;
    }
    double dt = options.fixed_step > 0.0 ? options.fixed_step
                : stable_rule             ? options.cfl * 2.0 / omega_now()
                                          : options.cfl * h / scan.max_signal_speed;
    observer.step_rule(dt);
    if (!std::isfinite(dt) || dt < smallest_step) {
      out.failure_reason = "time step collapsed";
      out.failure_detail = std::string(stable_rule ? "stable-rule" : "CFL") + " step " + std::to_string(dt) + " s";
      out.failure_time = t;
      out.failure_step = out.steps;
      break;
    }
    if (out.steps == 0) out.dt_first = dt;
    out.dt_min = out.steps == 0 ? dt : std::min(out.dt_min, dt);
    out.dt_max = out.steps == 0 ? dt : std::max(out.dt_max, dt);

    // Land on the next output time; split the last stretch in two rather than
    // leave a sliver of a step.
    const double target = options.output_times[next_output];
    const double remaining = target - t;
    bool lands = false;
    if (remaining <= dt * (1.0 + 1e-12)) {
      dt = remaining;
      lands = true;
    } else if (remaining < 2.0 * dt) {
      dt = 0.5 * remaining;
    }

    const double kick = options.time_integration == TimeIntegration::symplectic_euler ? dt
                        : out.steps == 0                                              ? 0.5 * dt
                                                                                      : 0.5 * (previous_dt + dt);
    out.particle_steps += static_cast<long long>(n());
    try {
      stepper.step(t, dt, kick);
    } catch (const std::runtime_error& e) {
      // A stage that cannot go on (a constraint system that does not factor):
      // the run ends here with what it has, as for an unhealthy particle.
      out.failure_reason = "stage failed";
      out.failure_detail = e.what();
      out.failure_time = t;
      out.failure_step = out.steps;
      break;
    }
    previous_dt = dt;
    ++out.steps;
    if (const std::string why = stepper.step_failure(); !why.empty()) {
      out.failure_reason = "no equilibrium";
      out.failure_detail = why;
      out.failure_time = t;
      out.failure_step = out.steps;
      break;
    }
    t = lands ? target : t + dt;
    observer.after_step(t, stepper);

    // After the last step only the health counts: no step is prepared.
    const bool last = lands && next_output + 1 == options.output_times.size();
    scan = last ? stepper.scan() : stepper.prepare_step(t);
    if (scan.first_unhealthy < n()) {
      fail(scan, t);
      break;
    }
    if (lands) {
      observer.at_output(next_output, t, stepper);
      ++next_output;
      out.outputs_written = next_output;
      if (const auto [reason, detail] = observer.stop(); !reason.empty()) {
        out.failure_reason = reason;
        out.failure_detail = detail;
        out.failure_time = t;
        out.failure_step = out.steps;
        break;
      }
    }

    if (progress && seconds_since(last_report) >= progress_interval_seconds) {
      last_report = Clock::now();
      const double elapsed = seconds_since(start);
      const double rate = double(out.particle_steps) / elapsed;
      const double eta = t > 0.0 ? elapsed * (options.end_time - t) / t : 0.0;
      progress({out.steps, t, options.end_time, rate, eta, false});
    }
  }

  out.time_reached = t;
  out.completed = out.failure_reason.empty();
  out.wall_seconds = seconds_since(start);
  out.forcing_seconds = stepper.forcing_seconds();
  out.stage_seconds = stepper.stage_times();
  out.bytes_per_particle = stepper.bytes_per_particle();
  if (progress) {
    const double rate = out.wall_seconds > 0.0 ? double(out.particle_steps) / out.wall_seconds : 0.0;
    progress({out.steps, t, options.end_time, rate, 0.0, true});
  }
  return out;
}

}  // namespace mpmvv
