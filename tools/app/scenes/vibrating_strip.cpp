#include "vibrating_strip.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#ifdef MPMVV_HAVE_FFTW
#include "analytic/fft.hpp"
#endif

namespace mpmvv::app {

void set_up_vibrating_strip(SceneSetup& s, double length, int cells, int probe_points, double exact_period,
                            double exact_amplitude) {
  const double L = length;
  const double h = L / cells;
  s.grid = GridGeometry::walled(Vec2::Zero(), h, cells + 4, 2);
  const double height = 2.0 * h;
  s.body_is_rectangle(Vec2::Zero(), Vec2(L, height));
  ProbeLine line{"line_axis", ProbeQuantity::displacement_x, "reference_x", {}, {}, std::nullopt};
  line.reference = points_on_segment(Vec2(0.0, 0.5 * height), Vec2(L, 0.5 * height), probe_points);
  for (const Vec2& X : line.reference) line.parameter.push_back(X.x());
  s.lines.push_back(std::move(line));
  s.points.push_back({"point_free_end", ProbeQuantity::displacement_x, Vec2(L, 0.5 * height)});
  // Period and amplitude of the free end's history so far: the spectrum's
  // peak (FFTW) locates the period, the zero crossings measure it; NaN before
  // the history spans a whole period (the period needs FFTW).
  struct Vibration {
    double amplitude, period, spectral_period;
  };
  const auto vibration = [exact_period](const RunRecord& r) {
    const std::vector<double>& t = r.point_time;
    const std::vector<double>& u = r.point_values.front();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (t.size() < 8 || t.back() < exact_period) return Vibration{nan, nan, nan};
    double amplitude = 0.0;
    for (double x : u) amplitude = std::max(amplitude, std::abs(x));
#ifdef MPMVV_HAVE_FFTW
    const double spectral = 1.0 / analytic::dominant_frequency(t, u);
    return Vibration{amplitude, analytic::crossing_period(t, u, spectral), spectral};
#else
    return Vibration{amplitude, nan, nan};
#endif
  };
  s.extra_error_names = {"error_period", "error_amplitude"};
  s.extra_errors = [=](double, const RunRecord& r) {
    const Vibration v = vibration(r);
    return std::vector<double>{std::abs(v.period / exact_period - 1.0), std::abs(v.amplitude / exact_amplitude - 1.0)};
  };
  s.measure = [=](const RunRecord& r) -> Measurements {
    const Vibration v = vibration(r);
    return {{"amplitude", v.amplitude},
            {"amplitude_exact", exact_amplitude},
            {"amplitude_error", v.amplitude / exact_amplitude - 1.0},
            {"period", v.period},
            {"period_exact", exact_period},
            {"period_error", v.period / exact_period - 1.0},
            {"period_spectral_peak", v.spectral_period}};
  };
}

}  // namespace mpmvv::app
