#include "time_loop.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

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
                         const ProgressSink& progress, double progress_interval_seconds,
                         const Checkpoints& checkpoints) {
  if (options.output_times.empty() || options.output_times.back() != options.end_time)
    throw std::invalid_argument("output times must end at the end time");

  RunOutcome out;
  const auto start = Clock::now();
  auto last_report = start;
  auto last_save = start;
  // (The particle count may grow: split.hpp.)
  auto n = [&] { return stepper.model().particles.size(); };
  const double h = stepper.model().grid.h;
  // A step this small means the signal speed has run away.
  const double smallest_step = 1e-12 * options.end_time;

  // Everything a step hands to the next, apart from the stepper's state.
  LoopState s;
  if (checkpoints.resume) {
    s = *checkpoints.resume;
    s.resumed_at.push_back(s.t);
  }
  const double t_start = s.t;
  const long long particle_steps_start = s.particle_steps;
  auto stop_with = [&](std::string reason, std::string detail) {
    out.failure_reason = std::move(reason);
    out.failure_detail = std::move(detail);
    out.failure_time = s.t;
    out.failure_step = s.steps;
  };
  auto fail = [&](const ParticleScan& scan) {
    const ParticleFault fault = stepper.diagnose(scan.first_unhealthy);
    stop_with(fault.reason, fault.detail);
    out.failure_particle = static_cast<long long>(scan.first_unhealthy);
  };

  if (!checkpoints.resume) observer.initial(stepper);
  ParticleScan scan = stepper.prepare_step(s.t);
  if (scan.first_unhealthy < n()) fail(scan);

  // TimeStepRule::stable: the estimate of omega_max at time t, the last
  // measurement raised along the growth of the last two.
  const bool stable_rule = options.step_rule == TimeStepRule::stable && options.fixed_step <= 0.0;
  // False when the measurement gives no frequency; at the start that is a
  // stepper without one (an implicit step), later a run to stop with its data.
  auto measure = [&] {
    s.omega_before = s.omega_last;
    s.t_before = s.t_last;
    s.omega_last = stepper.largest_frequency(options.track_iterations);
    s.t_last = s.t;
    s.signal_at_measurement = scan.max_signal_speed;
    s.steps_at_measurement = s.steps;
    ++s.frequency_measurements;
    const bool measured = s.omega_last > 0.0 && std::isfinite(s.omega_last);
    if (!measured && s.steps == 0)
      throw std::invalid_argument("the stable time-step rule needs a stepper that measures its largest frequency "
                                  "(an explicit step)");
    return measured;
  };
  auto omega_now = [&] {
    if (!(s.omega_before > 0.0 && s.t_last > s.t_before)) return s.omega_last;
    return s.omega_last +
           std::max(0.0, (s.omega_last - s.omega_before) / (s.t_last - s.t_before)) * (s.t - s.t_last);
  };

  while (out.failure_reason.empty() && s.next_output < options.output_times.size()) {
    // Between two steps: the state is whole here, and saved when due.
    const bool signalled = stop_request().load(std::memory_order_relaxed);
    const bool paused = s.t >= checkpoints.pause_at;
    // A run resumed and stopped before its first step leaves the restart
    // file as it found it: the state in it is this state.
    const bool unchanged = checkpoints.resume && s.steps == checkpoints.resume->steps;
    if (checkpoints.save && !unchanged && (signalled || paused ||
                             (checkpoints.every_seconds > 0.0 &&
                              seconds_since(last_save) >= checkpoints.every_seconds))) {
      LoopState saved = s;
      saved.wall_seconds += seconds_since(start);
      checkpoints.save(saved);
      last_save = Clock::now();
    }
    if (signalled || paused) {
      stop_with(kInterrupted, signalled ? "stopped on request (a signal) before step " + std::to_string(s.steps + 1)
                                        : "paused at t = " + std::to_string(s.t) + " s before step " +
                                              std::to_string(s.steps + 1) + ", as asked");
      break;
    }
    const bool due = s.steps == 0 || s.steps - s.steps_at_measurement >= options.track_every ||
                     scan.max_signal_speed > options.track_growth * s.signal_at_measurement;
    if (stable_rule && due && !measure()) {
      stop_with("stable step unmeasured", "the power iteration for omega_max gave " + std::to_string(s.omega_last) +
                                              " rad/s");
      break;
    }
    double dt = options.fixed_step > 0.0 ? options.fixed_step
                : stable_rule             ? options.cfl * 2.0 / omega_now()
                                          : options.cfl * h / scan.max_signal_speed;
    observer.step_rule(dt);
    if (!std::isfinite(dt) || dt < smallest_step) {
      // Say which number made it small: the end time asked for, or the
      // material's signal speed against the cell.
      stop_with("time step collapsed",
                fmt::format("{} step {:.3g} s is below {:.0e} of end_time = {:.3g} s (the run would take over {:.0e} "
                            "steps); signal speed {:.3g} m/s over h = {:.3g} m",
                            stable_rule ? "the stable-rule" : "the CFL", dt, smallest_step / options.end_time,
                            options.end_time, options.end_time / smallest_step, scan.max_signal_speed, h));
      break;
    }
    if (s.steps == 0) s.dt_first = dt;
    s.dt_min = s.steps == 0 ? dt : std::min(s.dt_min, dt);
    s.dt_max = s.steps == 0 ? dt : std::max(s.dt_max, dt);

    // Land on the next output time; split the last stretch in two rather than
    // leave a sliver of a step.
    const double target = options.output_times[s.next_output];
    const double remaining = target - s.t;
    bool lands = false;
    if (remaining <= dt * (1.0 + 1e-12)) {
      dt = remaining;
      lands = true;
    } else if (remaining < 2.0 * dt) {
      dt = 0.5 * remaining;
    }

    const double kick = options.time_integration == TimeIntegration::symplectic_euler ? dt
                        : s.steps == 0                                                ? 0.5 * dt
                                                                                      : 0.5 * (s.previous_dt + dt);
    s.particle_steps += static_cast<long long>(n());
    try {
      stepper.step(s.t, dt, kick);
    } catch (const std::runtime_error& e) {
      // A stage that cannot go on (a constraint system that does not factor):
      // the run ends here with what it has, as for an unhealthy particle.
      stop_with("stage failed", e.what());
      break;
    }
    s.previous_dt = dt;
    ++s.steps;
    if (const std::string why = stepper.step_failure(); !why.empty()) {
      stop_with("no equilibrium", why);
      break;
    }
    s.t = lands ? target : s.t + dt;
    observer.after_step(s.t, stepper);

    // After the last step only the health counts: no step is prepared.
    const bool last = lands && s.next_output + 1 == options.output_times.size();
    try {
      scan = last ? stepper.scan() : stepper.prepare_step(s.t);
    } catch (const std::runtime_error& e) {
      stop_with("stage failed", e.what());  // the map that prepares the next step, as a step's stage above
      break;
    }
    if (scan.first_unhealthy < n()) {
      fail(scan);
      break;
    }
    if (lands) {
      observer.at_output(s.next_output, s.t, stepper);
      ++s.next_output;
      if (const auto [reason, detail] = observer.stop(); !reason.empty()) {
        stop_with(reason, detail);
        break;
      }
    }

    if (progress && seconds_since(last_report) >= progress_interval_seconds) {
      last_report = Clock::now();
      const double elapsed = seconds_since(start);
      const double rate = double(s.particle_steps - particle_steps_start) / elapsed;
      const double eta = s.t > t_start ? elapsed * (options.end_time - s.t) / (s.t - t_start) : 0.0;
      progress({s.steps, s.t, options.end_time, rate, eta, false});
    }
  }

  out.time_reached = s.t;
  out.completed = out.failure_reason.empty();
  out.steps = s.steps;
  out.particle_steps = s.particle_steps;
  out.dt_first = s.dt_first;
  out.dt_min = s.dt_min;
  out.dt_max = s.dt_max;
  out.frequency_measurements = s.frequency_measurements;
  out.outputs_written = s.next_output;
  out.resumed_at = s.resumed_at;
  const double this_part = seconds_since(start);
  out.wall_seconds = s.wall_seconds + this_part;
  out.forcing_seconds = stepper.forcing_seconds();
  out.stage_seconds = stepper.stage_times();
  out.bytes_per_particle = stepper.bytes_per_particle();
  if (progress) {
    const double rate = this_part > 0.0 ? double(s.particle_steps - particle_steps_start) / this_part : 0.0;
    progress({s.steps, s.t, options.end_time, rate, 0.0, true});
  }
  return out;
}

}  // namespace mpmvv
