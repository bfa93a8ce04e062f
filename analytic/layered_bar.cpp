#include "layered_bar.hpp"

#include <algorithm>
#include <numbers>
#include <stdexcept>
#include <string>

#include "kinsol.hpp"

namespace mpmvv::analytic {

double LayeredBar::first_frequency(double tolerance) const {
  if (!(length_1 > 0.0 && length_2 > 0.0 && modulus_1 > 0.0 && modulus_2 > 0.0 && density_1 > 0.0 && density_2 > 0.0))
    throw std::invalid_argument("a layered bar needs positive lengths, moduli and densities");
  // The residual rises from -Z1/Z2 at 0 to sin * sin > 0 at the first pole of
  // a tangent; halve the bracket to a thousandth of its width so that Newton
  // starts beside the first root and cannot reach another.
  double low = 0.0;
  double high = std::numbers::pi / (2.0 * std::max(length_1 / wave_speed_1(), length_2 / wave_speed_2()));
  const double width = high;
  while (high - low > 1e-3 * width) {
    const double middle = 0.5 * (low + high);
    (frequency_residual(middle) < 0.0 ? low : high) = middle;
  }
  // In units of the bracket's width, so that the tolerance is relative.
  const NonlinearSolution s = solve_nonlinear(
      [&](const std::vector<double>& u, std::vector<double>& f) { f[0] = frequency_residual(u[0] * width); },
      {0.5 * (low + high) / width}, tolerance);
  const double omega = s.u[0] * width;
  if (!(omega > low - 1e-3 * width && omega < high + 1e-3 * width))
    throw std::runtime_error("KINSOL left the bracket of the first frequency: " + std::to_string(omega) +
                             " not in [" + std::to_string(low) + ", " + std::to_string(high) + "]");
  return omega;
}

}  // namespace mpmvv::analytic
