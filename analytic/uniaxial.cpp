#include "uniaxial.hpp"

#include <cmath>

#include "kinsol.hpp"

namespace mpmvv::analytic {

namespace {

// sigma_yy of the neo-Hookean solid, eq. 2.2, for F = diag(l1, l2, l3).
double lateral_stress(double lambda, double mu, double l1, double l2, double l3) {
  const double J = l1 * l2 * l3;
  return lambda * std::log(J) / J + mu / J * (l2 * l2 - 1.0);
}

NeoHookeanBar::State solve(double lambda, double mu, double l1, bool plane_strain) {
  auto l3 = [&](double l2) { return plane_strain ? 1.0 : l2; };
  // Scaled by mu so that the tolerance is relative to the material's stiffness.
  const NonlinearSolution s = solve_nonlinear(
      [&](const std::vector<double>& u, std::vector<double>& f) {
        f[0] = u[0] > 0.0 ? lateral_stress(lambda, mu, l1, u[0], l3(u[0])) / mu : NAN;
      },
      {1.0}, 1e-13);
  const double l2 = s.u[0];
  const double J = l1 * l2 * l3(l2);
  return {l2, lambda * std::log(J) / J + mu / J * (l1 * l1 - 1.0), J, s.iterations};
}

}  // namespace

NeoHookeanBar::State NeoHookeanBar::plane_strain(double axial_stretch) const {
  return solve(lambda, mu, axial_stretch, true);
}

NeoHookeanBar::State NeoHookeanBar::uniaxial_stress(double axial_stretch) const {
  return solve(lambda, mu, axial_stretch, false);
}

}  // namespace mpmvv::analytic
