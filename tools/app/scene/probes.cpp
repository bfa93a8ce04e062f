#include "probes.hpp"

#include <cmath>
#include <numbers>

#include "solver/io/state_archive.hpp"
#ifdef MPMVV_HAVE_FFTW
#include "analytic/fft.hpp"
#endif

namespace mpmvv::app {

using std::numbers::pi;

double probe_value(ProbeQuantity q, Geometry geometry, const Vec2& x, const Vec2& X, const Vec2& x_exact) {
  switch (q) {
    case ProbeQuantity::angular_displacement: {
      const double reference = std::atan2(X.y(), X.x());
      const double exact = std::atan2(x_exact.y(), x_exact.x()) - reference;
      return exact + std::remainder(std::atan2(x.y(), x.x()) - reference - exact, 2.0 * pi);
    }
    case ProbeQuantity::radial_displacement:
      return geometry == Geometry::axisymmetric ? x.x() - X.x() : x.norm() - X.norm();
    case ProbeQuantity::displacement_x: return x.x() - X.x();
    case ProbeQuantity::displacement_y: return x.y() - X.y();
  }
  return 0.0;
}

std::vector<Vec2> ProbeRecorder::tracer_references() const {
  std::vector<Vec2> X;
  for (const ProbeLine& line : setup_.lines) X.insert(X.end(), line.reference.begin(), line.reference.end());
  for (const ProbePoint& point : setup_.points) X.push_back(point.reference);
  X.insert(X.end(), circle_reference_.begin(), circle_reference_.end());
  return X;
}

void ProbeRecorder::seed_tracers(std::vector<Vec2>& tracers) {
  const mms::ExactSolution& s = *setup_.solution;
  line_first_.clear();
  for (const ProbeLine& line : setup_.lines) {
    line_first_.push_back(tracers.size());
    for (const Vec2& X : line.reference) tracers.push_back(s.position(X, 0.0));
  }
  line_records_.assign(setup_.lines.size(), {});
  point_first_ = tracers.size();
  for (const ProbePoint& point : setup_.points) tracers.push_back(s.position(point.reference, 0.0));
  point_simulated_.assign(setup_.points.size(), {});
  point_exact_.assign(setup_.points.size(), {});
  circle_first_ = tracers.size();
  circle_angle_.clear();
  circle_reference_.clear();
  if (setup_.circle) {
    for (int j = 0; j < setup_.circle->points; ++j) {
      const double Theta = 2.0 * pi * j / setup_.circle->points;
      const Vec2 X = setup_.circle->radius * Vec2(std::cos(Theta), std::sin(Theta));
      circle_angle_.push_back(Theta);
      circle_reference_.push_back(X);
      tracers.push_back(s.position(X, 0.0));
    }
  }
  history_time_.clear();
  history_values_.assign(setup_.history_names.size(), {});
}

void ProbeRecorder::after_step(double t, const Stepper& s) {
  if (setup_.history) {
    const std::vector<double> values = setup_.history(t, s);
    history_time_.push_back(t);
    for (std::size_t k = 0; k < values.size(); ++k) history_values_[k].push_back(values[k]);
  }
  point_time_.push_back(t);
  for (std::size_t k = 0; k < setup_.points.size(); ++k) {
    const ProbePoint& point = setup_.points[k];
    point_simulated_[k].push_back(value_at(point.quantity, s.model().tracers[point_first_ + k], point.reference, t));
    point_exact_[k].push_back(exact_at(point.quantity, point.reference, t));
  }
}

std::vector<double> ProbeRecorder::at_output(double t, const std::vector<Vec2>& tracers) {
  output_times_.push_back(t);
  std::vector<double> l1;
  for (std::size_t k = 0; k < setup_.lines.size(); ++k) {
    std::vector<double> sim, ex;
    l1.push_back(line_l1(k, tracers, t, &sim, &ex));
    line_records_[k].simulated.push_back(std::move(sim));
    line_records_[k].exact.push_back(std::move(ex));
  }
  if (setup_.circle) {
    std::vector<double> sim, ex, err;
    for (std::size_t j = 0; j < circle_reference_.size(); ++j) {
      const double value = value_at(setup_.circle->quantity, tracers[circle_first_ + j], circle_reference_[j], t);
      const double exact = exact_at(setup_.circle->quantity, circle_reference_[j], t);
      sim.push_back(value);
      ex.push_back(exact);
      err.push_back(value - exact);
    }
    circle_simulated_.push_back(std::move(sim));
    circle_exact_.push_back(std::move(ex));
#ifdef MPMVV_HAVE_FFTW
    circle_spectrum_.push_back(analytic::amplitude_spectrum(err));
#endif
  }
  return l1;
}

double ProbeRecorder::line_l1(std::size_t k, const std::vector<Vec2>& tracers, double t, std::vector<double>* simulated,
                              std::vector<double>* exact) const {
  const ProbeLine& line = setup_.lines[k];
  double l1 = 0.0;
  for (std::size_t i = 0; i < line.reference.size(); ++i) {
    const double value = value_at(line.quantity, tracers[line_first_[k] + i], line.reference[i], t);
    const double expected = exact_at(line.quantity, line.reference[i], t);
    if (simulated) simulated->push_back(value);
    if (exact) exact->push_back(expected);
    l1 += std::abs(value - expected);
  }
  return l1 / double(line.reference.size());
}

double ProbeRecorder::value_at(ProbeQuantity q, const Vec2& x, const Vec2& X, double t) const {
  return probe_value(q, setup_.geometry, x, X, setup_.solution->position(X, t));
}

double ProbeRecorder::exact_at(ProbeQuantity q, const Vec2& X, double t) const {
  const Vec2 x = setup_.solution->position(X, t);
  return probe_value(q, setup_.geometry, x, X, x);
}

void ProbeRecorder::persist(StateArchive& a) {
  a.field("line_records", line_records_);
  a.field("point_time", point_time_);
  a.field("point_simulated", point_simulated_);
  a.field("point_exact", point_exact_);
  a.field("circle_simulated", circle_simulated_);
  a.field("circle_exact", circle_exact_);
  a.field("circle_spectrum", circle_spectrum_);
  a.field("output_times", output_times_);
  a.field("history_time", history_time_);
  a.field("history_values", history_values_);
}

}  // namespace mpmvv::app
