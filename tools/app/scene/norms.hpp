// Norms: the error columns of /errors that every scene with an exact motion
// carries, measured over all particles against the exact solution at their
// reference positions, and what each column means (stored with them).
#pragma once

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mms/exact_solution.hpp"
#include "solver/model.hpp"
#include "solver/time_loop.hpp"
#include "tools/app/scene/setup.hpp"

namespace mpmvv::app {

class ProbeRecorder;  // probes.hpp

// The columns, in order, after each probe line's L1_<line>.
inline constexpr const char* kParticleNorms[] = {
    "particle_L1",          "particle_L2",          "particle_Linf",         "particle_pressure_L2",
    "particle_deformation_L2", "particle_velocity_L2", "exact_displacement_L2", "particle_relative_L2_integrated"};

// The columns a scene set up as `setup` writes, in order: each probe line's
// L1_<line>, the particle norms with an exact motion, the scene's own. An
// external program's run writes those of them its output allows.
std::vector<std::string> error_columns(const SceneSetup& setup);

// What every column means (eq. 3.1 of 000_1dbcb8acb6dddab9.txt for the lines).
const char* norm_definitions();

// The unit of an /errors column: a line's L1 in its quantity's (rad or m),
// the particle norms' own (m, Pa, m/s; 1 for F and the time-integrated
// relative norm), 1 for a scene's relative error_* columns.
std::string error_unit(const std::string& column, const std::vector<ProbeLine>& lines);

// Sums over the particles, weighted by reference volume V_p0, of the
// displacement error e_p = |x_p - x_exact(X_p, t)| (e, e^2, its largest)
// and of the exact displacement |x_exact - X_p|^2.
struct DisplacementSums {
  double weight = 0.0, l1 = 0.0, l2 = 0.0, linf = 0.0, exact2 = 0.0;
};
DisplacementSums displacement_sums(const Particles& P, const mms::ExactSolution& solution, double t);

// Reference-volume-weighted sums of the squared errors of the in-plane mean
// stress, of F (with F_33) and of the velocity, the exact motion's angular
// momentum over the same particles, and J_p / J_exact of each particle into
// `j_ratio`; the same bits for a given thread count.
struct FieldErrors {
  double pressure = 0.0, deformation = 0.0, velocity = 0.0, spin = 0.0;
};
FieldErrors field_errors(const Particles& P, const mms::ExactSolution& solution, Geometry geometry, double t,
                         std::vector<double>& j_ratio);

// The time-integrated relative L2 displacement error, the norm other codes
// publish for the ring (the vortex of the total Lagrangian MPM literature):
//   sqrt( int_0^t sum_p V_p0 |x_p - x_exact|^2 dt / int_0^t sum_p V_p0 |x_exact - X_p|^2 dt ),
// both integrals by the trapezoid rule over the start and the output times.
struct TimeIntegral {
  double time = 0.0, error2 = 0.0, exact2 = 0.0;  // the last point
  double error_integral = 0.0, exact_integral = 0.0;
  bool started = false;
  void add(double t, double e2, double u2) {
    if (started) {
      error_integral += 0.5 * (t - time) * (e2 + error2);
      exact_integral += 0.5 * (t - time) * (u2 + exact2);
    }
    time = t;
    error2 = e2;
    exact2 = u2;
    started = true;
  }
  double relative() const {
    return exact_integral > 0.0 ? std::sqrt(error_integral / exact_integral) : std::numeric_limits<double>::quiet_NaN();
  }
};

// The values of kParticleNorms at output time t, in their order (the time
// integral `integrated` taken to t), J_p / J_exact of each particle into
// `j_ratio` and the exact motion's angular momentum over the particles into
// `spin` (field_errors).
std::vector<double> particle_norms(const Particles& P, const mms::ExactSolution& solution, Geometry geometry, double t,
                                   TimeIntegral& integrated, std::vector<double>& j_ratio, double& spin);

// The error norms a static scene reads at its end, at time t, for the
// settling of each (settling.hpp): the lines' L1, the particle displacement
// norms and the scene's own columns.
std::vector<std::pair<std::string, double>> settling_norms(const SceneSetup& setup, const ErrorTable& errors,
                                                           const ProbeRecorder& probes, double t, const Stepper& s);

// SceneCase::exact_signal_fraction for a scene set up as `setup` with time
// loop `loop` (scene.hpp).
std::optional<double> exact_signal_fraction(const SceneSetup& setup, const TimeLoopOptions& loop,
                                            const std::string& norm, double time);

}  // namespace mpmvv::app
