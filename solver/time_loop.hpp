// Advances a stepper to the end time with the CFL time step, lands exactly on
// every output time, and turns a particle that stops the run into data: the
// status, the reason, the time, the step and the particle.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "stepper.hpp"

namespace mpmvv {

// How velocities sit in time. Both use the update of eqs. 1.72 and 1.76; they
// differ in the kick, the time over which the acceleration at t_n acts.
enum class TimeIntegration {
  // Velocities at t_n, kick = dt: first order (the update as written).
  symplectic_euler,
  // Velocities at half steps t_{n+1/2} (central differences, leapfrog): the
  // first kick is dt_0 / 2 and later kicks are (dt_{n-1} + dt_n) / 2, so
  // changing the step (CFL, landing on an output time) keeps second order.
  central_difference,
};

const char* to_string(TimeIntegration t);

// How long a step is.
enum class TimeStepRule {
  // dt = cfl h / max_p (c_p + |v_p|) (Stepper::prepare_step, stages.hpp: scan_particles).
  cfl,
  // dt = cfl 2 / omega_max: a fraction of the stable step of central
  // differences, omega_max measured by power iteration on the step's own
  // linearization (Stepper::largest_frequency) every `track_every` steps, or
  // sooner when the particles' wave-speed bound grows by `track_growth`, and
  // extrapolated in between along the growth of the last two measurements.
  // For a linearization that is symmetric (the total Lagrangian
  // formulation), where a particle-wise wave speed overstates the grid's
  // largest frequency: in the stiff vortex on 30 cells
  // (suites/stiff-vortex.toml) the particles' wave speed bound grows 48 times
  // as the ring twists, omega_max 5.8 times.
  stable,
};

const char* to_string(TimeStepRule r);

struct TimeLoopOptions {
  double end_time = 1.0;
  // dt = cfl h / max_p (c_p + |v_p|): the material's wave speed bound at the
  // particle's current state plus its speed.
  double cfl = 0.5;
  TimeStepRule step_rule = TimeStepRule::cfl;
  int track_every = 50;       // TimeStepRule::stable: steps between measurements of omega_max
  // TimeStepRule::stable: measure sooner when the particles' wave-speed bound
  // (ParticleScan::max_signal_speed) has grown by this factor since the last
  // measurement: the material stiffens faster than 50 steps follow when a
  // step is long (a soft ring), and the bound, which overstates omega_max,
  // grows at least as fast as it does (stiff vortex on 30 cells: 48 times
  // against 5.8 times).
  double track_growth = 1.1;
  int track_iterations = 20;  // power iterations per measurement, each from the same fixed start
  TimeIntegration time_integration = TimeIntegration::central_difference;
  // When positive, every step is this long instead of the CFL step (the load
  // steps of an implicit static run).
  double fixed_step = 0.0;
  // Strictly increasing, positive; the last one is the end time.
  std::vector<double> output_times;
};

struct RunOutcome {
  bool completed = false;
  std::string failure_reason;  // empty when completed
  std::string failure_detail;
  double failure_time = std::numeric_limits<double>::quiet_NaN();
  long long failure_step = -1;
  long long failure_particle = -1;
  double time_reached = 0.0;
  long long steps = 0;
  long long particle_steps = 0;
  double wall_seconds = 0.0;
  double forcing_seconds = 0.0;
  StageTimes stage_seconds;         // the step's stages (stage_times.hpp), body force apart
  double bytes_per_particle = 0.0;  // held by the particles, the stepper and its body force at the end
                                    // (Stepper::bytes_per_particle)
  double dt_first = std::numeric_limits<double>::quiet_NaN();  // from the CFL condition
  double dt_min = std::numeric_limits<double>::quiet_NaN();
  double dt_max = std::numeric_limits<double>::quiet_NaN();
  long long frequency_measurements = 0;  // TimeStepRule::stable: how often omega_max was measured
  std::size_t outputs_written = 0;
  std::vector<double> resumed_at;  // the times the run went on from a restart file (Checkpoints)
};

class RunObserver {
 public:
  virtual ~RunObserver() = default;
  virtual void initial(const Stepper&) {}
  virtual void after_step(double /*t*/, const Stepper&) {}
  // The step the time-step rule gave before this step (before any shortening
  // to land on an output time).
  virtual void step_rule(double /*dt*/) {}
  virtual void at_output(std::size_t /*index*/, double /*t*/, const Stepper&) {}
  // After an output: a reason to stop the run there (and its detail), when
  // the observer has one (an energy blow-up); empty to go on.
  virtual std::pair<std::string, std::string> stop() const { return {}; }
};

struct Progress {
  long long step;
  double time;
  double end_time;
  double particle_steps_per_second;
  double eta_seconds;
  bool final;
};
using ProgressSink = std::function<void(const Progress&)>;

// A request to end the run before its next step, with what it has: the
// failure reason "interrupted" (RunOutcome), so that whatever reads the
// results knows them to be incomplete. Process-wide, because signals are:
// `mpmvv run` sets it from its SIGINT and SIGTERM handlers (a lock-free atomic
// store is safe there).
std::atomic<bool>& stop_request();
inline constexpr const char* kInterrupted = "interrupted";  // the failure reason and status of such a run

// Where a run stands between two steps: with the stepper's state
// (Stepper::persist) and its observer's, what a restart file holds for the
// run to go on as if it had never stopped.
struct LoopState {
  double t = 0.0;
  double previous_dt = 0.0;  // the central-difference kick's half of the last step
  std::size_t next_output = 0;
  // TimeStepRule::stable: the last two measurements of omega_max and when
  // they were made.
  double omega_last = 0.0, omega_before = 0.0, t_last = 0.0, t_before = 0.0;
  double signal_at_measurement = 0.0;
  long long steps_at_measurement = 0;
  // So far (RunOutcome).
  long long steps = 0, particle_steps = 0, frequency_measurements = 0;
  double dt_first = std::numeric_limits<double>::quiet_NaN();
  double dt_min = std::numeric_limits<double>::quiet_NaN();
  double dt_max = std::numeric_limits<double>::quiet_NaN();
  double wall_seconds = 0.0;       // of the parts run before this one
  std::vector<double> resumed_at;  // the times the run went on from a restart file

  template <class Archive>
  void persist(Archive& a) {
    a.field("t", t);
    a.field("previous_dt", previous_dt);
    a.field("next_output", next_output);
    a.field("omega_last", omega_last);
    a.field("omega_before", omega_before);
    a.field("t_last", t_last);
    a.field("t_before", t_before);
    a.field("signal_at_measurement", signal_at_measurement);
    a.field("steps_at_measurement", steps_at_measurement);
    a.field("steps", steps);
    a.field("particle_steps", particle_steps);
    a.field("frequency_measurements", frequency_measurements);
    a.field("dt_first", dt_first);
    a.field("dt_min", dt_min);
    a.field("dt_max", dt_max);
    a.field("wall_seconds", wall_seconds);
    a.field("resumed_at", resumed_at);
  }
};

// Saving a run's state as it goes, and going on from a saved state.
struct Checkpoints {
  // Saves the state between two steps (the caller adds the stepper's and the
  // observer's); a save that fails is the caller's to report, not a reason
  // to end the run.
  std::function<void(const LoopState&)> save;
  double every_seconds = 0.0;  // wall time between saves; 0: only when the run stops early
  // The run stops before its first step from this time on, as interrupted,
  // with its state saved.
  double pause_at = std::numeric_limits<double>::infinity();
  // Where to go on from (the stepper and the observer already hold their
  // saved state); null: from t = 0.
  const LoopState* resume = nullptr;
};

// With checkpoints, the state is saved every `every_seconds` and when the run
// stops early (a signal, pause_at); a run that ends otherwise saves none at
// its end.
RunOutcome run_time_loop(Stepper& stepper, const TimeLoopOptions& options, RunObserver& observer,
                         const ProgressSink& progress = {}, double progress_interval_seconds = 1.0,
                         const Checkpoints& checkpoints = {});

}  // namespace mpmvv
