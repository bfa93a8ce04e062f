// The axial vibration of a fixed-free bar (PROBLEMS.md section 5), no forcing:
// a strip between roller walls (uniaxial strain, c = sqrt((lambda + 2 mu) /
// rho)), its fixed end on the left wall and its free end short of the right
// one, started in its first mode, v0 = V sin(pi X / 2L). Probes: the line along
// the bar reads the displacement; the free end's history gives the period
// (FFTW) and the amplitude, against omega_1 = pi c / 2L and V / omega_1.
#include <cmath>

#include <fmt/format.h>

#include "analytic/vibrating_bar.hpp"
#ifdef MPMVV_HAVE_FFTW
#include "analytic/fft.hpp"
#endif
#include "tools/app/mms_scene.hpp"

namespace mpmvv::app {

namespace {

std::vector<KeySpec> keys() {
  const double inf = std::numeric_limits<double>::infinity();
  // Steel: one period 4 L / c = 6.71e-4 s for L = 1 m; five periods.
  std::vector<KeySpec> k = solver_keys(32, 0.00336, {0.00084, 0.00168, 0.00252, 0.00336});
  const std::vector<KeySpec> own = {
      {"length", KeyKind::real, 1.0, "L, the length of the bar [m]", 0.0, inf, true},
      {"velocity_amplitude", KeyKind::real, 1.0,
       "V of v0 = V sin(pi X / 2L) [m/s]; the strain amplitude is V / c", 0.0, inf, true},
      {"probe_points", KeyKind::integer, std::int64_t(51), "material points on the probe line", 2, 100000},
  };
  // Steel, E = 207 GPa, nu = 0.3.
  return problem_keys(std::move(k), own, material_keys("linear-elastic", 119.42e9, 79.615e9, 7850.0));
}

ProblemSetup setup(const Config& c) {
  ProblemSetup s;
  s.material = material_from(c);
  s.geometry = Geometry::plane_strain;
  s.force_free = true;
  const double L = c.real("length");
  const double M = p_wave_modulus(s.material);
  const analytic::VibratingBar bar{L, std::sqrt(M / c.real("density"))};
  const analytic::VibratingBarMotion motion{bar, c.real("velocity_amplitude")};
  s.solution = mms::make_solution(motion, s.material, c.real("density"), s.geometry);

  // The strip: two cells high between roller walls; the right wall four cells
  // beyond the free end.
  const int cells = int(c.integer("cells"));
  const double h = L / cells;
  s.grid = GridGeometry::walled(Vec2::Zero(), h, cells + 4, 2);
  const double height = 2.0 * h;
  s.contains = [L, height](const Vec2& X) { return X.x() >= 0.0 && X.x() <= L && X.y() >= 0.0 && X.y() <= height; };
#ifdef MPMVV_HAVE_CGAL
  s.body = Body::rectangle(Vec2::Zero(), Vec2(L, height));
#endif
  ProbeLine line{"line_axis", ProbeQuantity::displacement_x, "reference_x", {}, {}, std::nullopt};
  line.reference = points_on_segment(Vec2(0.0, 0.5 * height), Vec2(L, 0.5 * height), int(c.integer("probe_points")));
  for (const Vec2& X : line.reference) line.parameter.push_back(X.x());
  s.lines.push_back(std::move(line));
  s.points.push_back({"point_free_end", ProbeQuantity::displacement_x, Vec2(L, 0.5 * height)});
  const double V = motion.velocity_amplitude;
  // Period and amplitude of the free end's history so far: the spectrum's
  // peak (FFTW) locates the period, the zero crossings measure it; NaN before
  // the history spans a whole period (the period needs FFTW).
  struct Vibration {
    double amplitude, period, spectral_period;
  };
  const auto vibration = [bar](const RunRecord& r) {
    const std::vector<double>& t = r.point_time;
    const std::vector<double>& u = r.point_values.front();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (t.size() < 8 || t.back() < bar.period(1)) return Vibration{nan, nan, nan};
    double amplitude = 0.0;
    for (double x : u) amplitude = std::max(amplitude, std::abs(x));
#ifdef MPMVV_HAVE_FFTW
    const double spectral = 1.0 / analytic::dominant_frequency(t, u);
    return Vibration{amplitude, analytic::crossing_period(t, u, spectral), spectral};
#else
    return Vibration{amplitude, nan, nan};
#endif
  };
  const double exact_amplitude = V / bar.frequency(1);
  s.extra_error_names = {"error_period", "error_amplitude"};
  s.extra_errors = [=](double, const RunRecord& r) {
    const Vibration v = vibration(r);
    return std::vector<double>{std::abs(v.period / bar.period(1) - 1.0), std::abs(v.amplitude / exact_amplitude - 1.0)};
  };
  s.measure = [=](const RunRecord& r) -> Measurements {
    const Vibration v = vibration(r);
    return {{"amplitude", v.amplitude},
            {"amplitude_exact", exact_amplitude},
            {"amplitude_error", v.amplitude / exact_amplitude - 1.0},
            {"period", v.period},
            {"period_exact", bar.period(1)},
            {"period_error", v.period / bar.period(1) - 1.0},
            {"period_spectral_peak", v.spectral_period}};
  };
  return s;
}

}  // namespace

MmsProblem vibrating_bar_problem() {
  return {"vibrating-bar", "axial vibration of a fixed-free bar, first mode, no forcing (PROBLEMS.md section 5)", keys,
          setup};
}

}  // namespace mpmvv::app
