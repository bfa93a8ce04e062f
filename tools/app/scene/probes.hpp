// Probes: the material points where a scene's error is measured, followed by
// tracers the solver moves with the grid velocity. A line is read at every
// output time (its mean |q_sim - q_exact| is eq. 3.1 of
// 000_1dbcb8acb6dddab9.txt), a point after every step, a circle at every
// output time with the amplitude spectrum of its error; a scene's own scalar
// histories after every step.
#pragma once

#include <cstddef>
#include <vector>

#include "solver/stepper.hpp"
#include "tools/app/scene/setup.hpp"

namespace mpmvv::app {

// The quantity at a material point with current position x, reference X and
// exact current position x_exact. Angles are unwrapped about the exact value
// (the error stays far below pi).
double probe_value(ProbeQuantity q, Geometry geometry, const Vec2& x, const Vec2& X, const Vec2& x_exact);

class ProbeRecorder {
 public:
  explicit ProbeRecorder(const SceneSetup& setup) : setup_(setup) {}

  // Appends a tracer for each probe's material point, at its exact position
  // at t = 0, and forgets what was recorded.
  void seed_tracers(std::vector<Vec2>& tracers);

  // The probe points and the scene's histories after a step at time t.
  void after_step(double t, const Stepper& s);

  // The material points of the tracers seed_tracers appended, in their order.
  std::vector<Vec2> tracer_references() const;

  // Records the lines and the circle at output time t; returns each line's L1.
  std::vector<double> at_output(double t, const std::vector<Vec2>& tracers);

  // Eq. 3.1 on line k at time t: the mean over its material points of
  // |q_sim - q_exact|; their values into `simulated` and `exact` when given.
  double line_l1(std::size_t k, const std::vector<Vec2>& tracers, double t, std::vector<double>* simulated = nullptr,
                 std::vector<double>* exact = nullptr) const;

  // The quantity q at the material point X with current position x, and its exact value, at time t.
  double value_at(ProbeQuantity q, const Vec2& x, const Vec2& X, double t) const;
  double exact_at(ProbeQuantity q, const Vec2& X, double t) const;

  // The probe points' histories so far, for a scene's own errors and measurements.
  RunRecord record(const Stepper& s) const { return RunRecord{point_time_, point_simulated_, s}; }

  // What has been recorded, under its restart-file names (the tracers are
  // rebuilt as the case is set up).
  void persist(StateArchive& a);

  // What the results file writes (results_file.cpp).
  struct LineRecord {
    std::vector<std::vector<double>> simulated, exact;  // per output time

    template <class Archive>
    void persist(Archive& a) {
      a.field("simulated", simulated);
      a.field("exact", exact);
    }
  };
  const SceneSetup& setup() const { return setup_; }
  const std::vector<double>& output_times() const { return output_times_; }
  const std::vector<LineRecord>& line_records() const { return line_records_; }
  const std::vector<double>& point_time() const { return point_time_; }
  const std::vector<std::vector<double>>& point_simulated() const { return point_simulated_; }
  const std::vector<std::vector<double>>& point_exact() const { return point_exact_; }
  const std::vector<double>& circle_angle() const { return circle_angle_; }
  const std::vector<std::vector<double>>& circle_simulated() const { return circle_simulated_; }
  const std::vector<std::vector<double>>& circle_exact() const { return circle_exact_; }
  const std::vector<std::vector<double>>& circle_spectrum() const { return circle_spectrum_; }
  const std::vector<double>& history_time() const { return history_time_; }
  const std::vector<std::vector<double>>& history_values() const { return history_values_; }

 private:
  const SceneSetup& setup_;
  std::vector<std::size_t> line_first_;  // each line's first tracer
  std::vector<LineRecord> line_records_;
  std::size_t point_first_ = 0;
  std::vector<double> point_time_;
  std::vector<std::vector<double>> point_simulated_, point_exact_;
  std::size_t circle_first_ = 0;
  std::vector<double> circle_angle_;
  std::vector<Vec2> circle_reference_;
  std::vector<std::vector<double>> circle_simulated_, circle_exact_, circle_spectrum_;
  std::vector<double> output_times_;
  std::vector<double> history_time_;
  std::vector<std::vector<double>> history_values_;
};

}  // namespace mpmvv::app
