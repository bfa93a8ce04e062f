// Wall time of the stages of the explicit step, summed over a run, and the
// memory the particles hold: what the throughput benchmark breaks a step into
// (tools/bench/throughput.cpp), so that a change to the step can be judged
// from its output alone. A clock reads twice per stage per step, some 50 ns
// against a stage's milliseconds.
#pragma once

#include <chrono>

namespace mpmvv {

struct StageTimes {
  double map = 0.0;     // particles to grid: mass, momentum, forces (with the time-step scan when the map makes it)
  double grid = 0.0;    // grid motion from the node sums: walls, constraints, rest points, contact
  double update = 0.0;  // grid to particles: velocities, positions, F; tracers; CPDI corners
  double stress = 0.0;  // the constitutive update, with the dilatation remedy and bulk viscosity when run
  double scan = 0.0;    // time-step scans made as passes of their own (Stepper::scan)
};

// Adds the time from its construction to its end to `total`.
class StageClock {
 public:
  explicit StageClock(double& total) : total_(total), start_(std::chrono::steady_clock::now()) {}
  ~StageClock() { total_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  StageClock(const StageClock&) = delete;
  StageClock& operator=(const StageClock&) = delete;

 private:
  double& total_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace mpmvv
