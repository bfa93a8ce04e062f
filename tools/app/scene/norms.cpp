#include "norms.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

#include "probes.hpp"
#include "solver/parallel.hpp"

namespace mpmvv::app {

std::string error_unit(const std::string& column, const std::vector<ProbeLine>& lines) {
  for (const ProbeLine& line : lines)
    if (column == "L1_" + line.name) return line.quantity == ProbeQuantity::angular_displacement ? "rad" : "m";
  static constexpr std::pair<const char*, const char*> kUnits[] = {
      {"particle_L1", "m"},          {"particle_L2", "m"},
      {"particle_Linf", "m"},        {"particle_pressure_L2", "Pa"},
      {"particle_deformation_L2", "1"}, {"particle_velocity_L2", "m/s"},
      {"exact_displacement_L2", "m"}, {"particle_relative_L2_integrated", "1"}};
  for (const auto& [name, unit] : kUnits)
    if (column == name) return unit;
  return column.rfind("error_", 0) == 0 ? "1" : "";
}

const char* norm_definitions() {
  return "L1_<line>: eq. 3.1 of 000_1dbcb8acb6dddab9.txt, the mean over the line's material points of "
         "|q_sim - q_exact| for the line's quantity (its 'quantity' attribute; rad or m); particle_L1, "
         "particle_L2, particle_Linf: norms of the displacement error |x_p - x_exact(X_p, t)| over all "
         "particles, weighted by reference volume (m); particle_pressure_L2: the reference-volume-weighted RMS error "
         "of the in-plane mean stress -(sigma_xx + sigma_yy)/2 (Pa); particle_deformation_L2: the reference-volume-"
         "weighted RMS of |F_p - F_exact(X_p, t)| (Frobenius, with F_33; dimensionless); particle_velocity_L2: the reference-volume-"
         "weighted RMS of |v_p - v_exact(X_p, t)| (m/s); exact_displacement_L2: the reference-volume-"
         "weighted RMS of the exact displacement |x_exact - X_p| (m); particle_relative_L2_integrated: "
         "sqrt(int_0^t sum V_p0 |x_p - x_exact|^2 dt / int_0^t sum V_p0 |x_exact - X_p|^2 dt), trapezoid rule over "
         "the start and the output times (the norm the total Lagrangian MPM literature reports for the ring); "
         "error_*: the scene's own relative errors "
         "against its exact "
         "solution (reports/results-format.md)";
}

DisplacementSums displacement_sums(const Particles& P, const mms::ExactSolution& solution, double t) {
  DisplacementSums d;
  for (std::size_t p = 0; p < P.size(); ++p) {
    const Vec2 x_exact = solution.position(P.reference_position[p], t);
    const double e = (P.position[p] - x_exact).norm();
    const double w = P.reference_volume[p];
    d.weight += w;
    d.l1 += w * e;
    d.l2 += w * e * e;
    d.linf = std::isnan(e) ? e : std::max(d.linf, e);  // a lost particle makes the norm NaN, as it does L1
    d.exact2 += w * (x_exact - P.reference_position[p]).squaredNorm();
  }
  return d;
}

// The in-plane mean stress -(sigma_xx + sigma_yy) / 2 against the exact one:
// its volume-weighted RMS error shows the pressure oscillation of a nearly
// incompressible solid (volumetric locking). The deformation gradient's error
// |F_p - F(X_p, t)| (Frobenius, the out-of-plane stretch included) is the
// strain the stress is computed from: a method can place its particles to
// second order while each particle's F carries an error of first order from
// particle to particle, which the displacement norms average away. The
// velocity's error |v_p - v(X_p, t)| holds what the positions integrate: a
// drift, and the elastic waves a method excites and the exact motion does not
// have (their positions' share is their amplitude over their frequency). With
// them the exact motion's angular momentum over the same particles, the
// reference its monitor is read against (the ring's spin,
// suites/stiff-vortex.toml).
FieldErrors field_errors(const Particles& P, const mms::ExactSolution& solution, Geometry geometry, double t,
                         std::vector<double>& j_ratio) {
  const std::size_t n = P.size();
  const bool axisymmetric = geometry == Geometry::axisymmetric;  // F_33 = F_theta (out_of_plane_stretch)
  j_ratio.resize(n);
  ThreadOrderedSums<4> sums;  // pressure, deformation, velocity, spin: the same bits for a given thread count
#pragma omp parallel
  {
    double pressure = 0.0, deformation = 0.0, velocity = 0.0, spin = 0.0;
#pragma omp for schedule(static)
    for (std::size_t p = 0; p < n; ++p) {
      const mms::ExactFields f = solution.state(P.reference_position[p], t);
      spin += P.mass[p] * (f.position.x() * f.velocity.y() - f.position.y() * f.velocity.x());
      j_ratio[p] = determinant(P.deformation_gradient[p]) * (axisymmetric ? P.hoop_stretch[p] : 1.0) /
                   (determinant(f.deformation_gradient) * f.hoop_stretch);
      const double e = 0.5 * ((P.stress[p] - f.cauchy_stress).trace());
      pressure += P.reference_volume[p] * e * e;
      const double e33 = (axisymmetric ? P.hoop_stretch[p] : 1.0) - f.hoop_stretch;
      const double e_in_plane = (P.deformation_gradient[p] - f.deformation_gradient).squaredNorm();
      deformation += P.reference_volume[p] * (e_in_plane + e33 * e33);
      velocity += P.reference_volume[p] * (P.velocity[p] - f.velocity).squaredNorm();
    }
    sums.keep({pressure, deformation, velocity, spin});
  }
  const auto [pressure, deformation, velocity, spin] = sums.total();
  return {pressure, deformation, velocity, spin};
}

std::vector<double> particle_norms(const Particles& P, const mms::ExactSolution& solution, Geometry geometry, double t,
                                   TimeIntegral& integrated, std::vector<double>& j_ratio, double& spin) {
  const DisplacementSums d = displacement_sums(P, solution, t);
  const double weight = d.weight;
  const FieldErrors f = field_errors(P, solution, geometry, t, j_ratio);
  spin = f.spin;
  integrated.add(t, d.l2, d.exact2);
  return {d.l1 / weight,
          std::sqrt(d.l2 / weight),
          d.linf,
          std::sqrt(f.pressure / weight),
          std::sqrt(f.deformation / weight),
          std::sqrt(f.velocity / weight),
          std::sqrt(d.exact2 / weight),
          integrated.relative()};
}

std::vector<std::pair<std::string, double>> settling_norms(const SceneSetup& setup, const ErrorTable& errors,
                                                           const ProbeRecorder& probes, double t, const Stepper& s) {
  std::vector<std::pair<std::string, double>> norms;
  for (std::size_t k = 0; k < setup.lines.size(); ++k)
    norms.push_back({errors.columns[k].first, probes.line_l1(k, s.model().tracers, t)});
  if (setup.exact_motion) {
    const DisplacementSums d = displacement_sums(s.model().particles, *setup.solution, t);
    norms.push_back({"particle_L1", d.l1 / d.weight});
    norms.push_back({"particle_L2", std::sqrt(d.l2 / d.weight)});
    norms.push_back({"particle_Linf", d.linf});
  }
  if (setup.extra_errors) {
    const std::vector<double> values = setup.extra_errors(t, probes.record(s));
    for (std::size_t k = 0; k < values.size() && k < setup.extra_error_names.size(); ++k)
      norms.push_back({setup.extra_error_names[k], values[k]});
  }
  return norms;
}

std::vector<std::string> error_columns(const SceneSetup& setup) {
  std::vector<std::string> names;
  for (const ProbeLine& line : setup.lines) names.push_back("L1_" + line.name);
  if (setup.exact_motion) names.insert(names.end(), std::begin(kParticleNorms), std::end(kParticleNorms));
  names.insert(names.end(), setup.extra_error_names.begin(), setup.extra_error_names.end());
  return names;
}

std::optional<double> exact_signal_fraction(const SceneSetup& setup, const TimeLoopOptions& loop,
                                            const std::string& norm, double time) {
  if (!setup.solution) return std::nullopt;
  if (std::isnan(time)) time = loop.end_time;
  std::function<double(double)> signal;
  if (norm.starts_with("L1_")) {
    const auto line = std::find_if(setup.lines.begin(), setup.lines.end(),
                                   [&](const ProbeLine& l) { return "L1_" + l.name == norm; });
    if (line == setup.lines.end() || line->reference.empty()) return std::nullopt;
    signal = [&setup, &line = *line](double t) {
      double sum = 0.0;
      for (const Vec2& X : line.reference) {
        const Vec2 x = setup.solution->position(X, t);
        sum += std::abs(probe_value(line.quantity, setup.geometry, x, X, x));
      }
      return sum / double(line.reference.size());
    };
  } else if (norm == "particle_L1" || norm == "particle_L2" || norm == "particle_Linf") {
    // The body sampled on a 48 x 48 lattice over the walls' box.
    std::vector<Vec2> body;
    const Vec2 lo = setup.grid.wall_lower(), hi = setup.grid.wall_upper();
    for (int j = 0; j < 48; ++j)
      for (int i = 0; i < 48; ++i) {
        const Vec2 X = lo + (hi - lo).cwiseProduct(Vec2((i + 0.5) / 48.0, (j + 0.5) / 48.0));
        if (setup.contains(X)) body.push_back(X);
      }
    if (body.empty()) return std::nullopt;
    signal = [&setup, body = std::move(body)](double t) {
      double sum = 0.0;
      for (const Vec2& X : body) sum += (setup.solution->position(X, t) - X).squaredNorm();
      return std::sqrt(sum / double(body.size()));
    };
  } else {
    return std::nullopt;
  }
  std::vector<double> times = loop.output_times;
  if (times.empty() || times.back() < loop.end_time) times.push_back(loop.end_time);
  double largest = 0.0, at = std::numeric_limits<double>::quiet_NaN();
  for (double t : times) {
    const double s = signal(t);
    largest = std::max(largest, s);
    if (std::abs(t - time) <= 1e-9 * std::max(1.0, std::abs(time))) at = s;
  }
  if (!std::isfinite(at) || !(largest > 0.0)) return std::nullopt;
  return at / largest;
}

}  // namespace mpmvv::app
