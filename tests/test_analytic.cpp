// Exact solutions without manufactured forces (analytic/): each agrees with an
// independent statement of itself (a quadrature, a limit, a finite difference).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "analytic/hertz.hpp"
#include "analytic/uniaxial.hpp"
#include "analytic/vibrating_bar.hpp"
#ifdef MPMVV_HAVE_SUNDIALS
#include "analytic/kinsol.hpp"
#include "analytic/layered_bar.hpp"
#endif

namespace {

using namespace mpmvv::analytic;
using std::numbers::pi;

// Midpoint rule with n intervals.
template <class F>
double integrate(F f, double a, double b, int n = 200000) {
  const double h = (b - a) / n;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += f(a + (i + 0.5) * h);
  return sum * h;
}

// The steel plate and rigid disk of 004_5b499dc27e377c32.txt section 4.3.
const HertzCylinder kSteelCylinder{2.0e7, 2.0, contact_modulus_rigid(207e9, 0.3)};

}  // namespace

// The pressure profile carries the load, p0 has both closed forms, and the
// axis stresses start at -p0.
TEST(Hertz, CylinderPressureCarriesTheLoad) {
  const HertzCylinder& h = kSteelCylinder;
  const double a = h.half_width();
  EXPECT_NEAR(integrate([&](double x) { return h.pressure(x); }, -a, a) / h.load, 1.0, 1e-8);
  EXPECT_NEAR(h.peak_pressure() / std::sqrt(h.load * h.contact_modulus / (pi * h.radius)), 1.0, 1e-14);
  EXPECT_NEAR(h.axis_sigma_z(0.0) / h.peak_pressure(), -1.0, 1e-14);
  EXPECT_NEAR(h.axis_sigma_x(0.0) / h.peak_pressure(), -1.0, 1e-14);
  EXPECT_EQ(h.pressure(1.01 * a), 0.0);
}

// The largest shear on the axis is 0.300 p0 at z = 0.786 a (Johnson).
TEST(Hertz, CylinderLargestShearOnTheAxis) {
  const HertzCylinder& h = kSteelCylinder;
  const double a = h.half_width();
  double best = 0.0, depth = 0.0;
  for (int i = 1; i < 200000; ++i) {
    const double z = 3.0 * a * i / 200000.0;
    if (h.axis_shear(z) > best) {
      best = h.axis_shear(z);
      depth = z;
    }
  }
  EXPECT_NEAR(best / h.peak_pressure(), 0.300, 5e-4);
  EXPECT_NEAR(depth / a, 0.786, 5e-4);
}

// The sphere's pressure carries the load, and load and approach are inverse.
TEST(Hertz, SphereLoadAndApproachAgree) {
  const HertzSphere s{1000.0, 0.05, contact_modulus(210e9, 0.3, 70e9, 0.33)};
  const double a = s.contact_radius();
  const double carried = integrate([&](double r) { return 2.0 * pi * r * s.peak_pressure() * std::sqrt(1.0 - r * r / (a * a)); }, 0.0, a);
  EXPECT_NEAR(carried / s.load, 1.0, 1e-8);
  EXPECT_NEAR(HertzSphere::load_at_approach(s.approach(), s.radius, s.contact_modulus) / s.load, 1.0, 1e-13);
}

// The sphere's stresses on the axis: at the surface sigma_z = -p0 and
// sigma_r = -(1 + 2 nu) p0 / 2; sigma_z at depth equals the sum of
// Boussinesq's point-load stresses, -3 P z^3 / (2 pi rho^5), over the Hertz
// pressure (an independent integral); the largest shear (sigma_r - sigma_z)/2
// is 0.31 p0 at z = 0.48 a for nu = 0.3 (Johnson, section 3.4).
TEST(Hertz, SphereAxisStressesAgreeWithBoussinesq) {
  const double nu = 0.3;
  const HertzSphere s{1000.0, 0.05, contact_modulus_rigid(210e9, nu)};
  const double a = s.contact_radius(), p0 = s.peak_pressure();
  EXPECT_NEAR(s.axis_sigma_z(0.0) / p0, -1.0, 1e-15);
  EXPECT_NEAR(s.axis_sigma_r(0.0, nu) / p0, -(1.0 + 2.0 * nu) / 2.0, 1e-15);
  for (double z : {0.25 * a, a, 3.0 * a}) {
    // r = a sin(t) takes the square root's end point out of the integrand.
    const double boussinesq = integrate(
        [&](double t) {
          const double r = a * std::sin(t), rho2 = r * r + z * z;
          const double pressure = p0 * std::cos(t);
          return -3.0 * z * z * z / (2.0 * pi * std::pow(rho2, 2.5)) * pressure * 2.0 * pi * r * a * std::cos(t);
        },
        0.0, pi / 2.0);
    EXPECT_NEAR(s.axis_sigma_z(z) / boussinesq, 1.0, 1e-9) << "z / a = " << z / a;
  }
  double best = 0.0, depth = 0.0;
  for (int k = 1; k <= 20000; ++k) {
    const double z = 1e-4 * k * a;
    const double shear = 0.5 * (s.axis_sigma_r(z, nu) - s.axis_sigma_z(z));
    if (shear > best) best = shear, depth = z;
  }
  EXPECT_NEAR(best / p0, 0.31, 0.005);
  EXPECT_NEAR(depth / a, 0.48, 0.005);
}

// Plane strain small-strain formulas follow from 3D Hooke's law with
// eps_zz = 0 and sigma_yy = 0; plane stress and 3D give E and -nu; the seed's
// lateral change tends to -nu d eps at small strain.
TEST(Uniaxial, SmallStrainFormsFollowFromHookesLaw) {
  const double E = 207e9, nu = 0.3, eps = 1e-4;
  const SmallStrainBar bar{E, nu};
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  // sigma_yy = lambda (eps + eps_yy) + 2 mu eps_yy = 0 in plane strain.
  const double eps_yy = -lambda * eps / (lambda + 2 * mu);
  const double sigma_xx = lambda * (eps + eps_yy) + 2 * mu * eps;
  EXPECT_NEAR(bar.stress_plane_strain(eps) / sigma_xx, 1.0, 1e-12);
  EXPECT_NEAR(bar.lateral_strain_plane_strain(eps) / eps_yy, 1.0, 1e-12);
  EXPECT_EQ(bar.stress_3d(eps), E * eps);
  EXPECT_EQ(bar.lateral_strain_plane_stress(eps), -nu * eps);
  EXPECT_NEAR(bar.seed_lateral_change(1.0, eps) / (-nu * eps), 1.0, 1e-3);
  EXPECT_NEAR(bar.shear_stress(1e-3) / (mu * 1e-3), 1.0, 1e-14);
}

// A fixed-free bar: the first-mode solution meets the wave equation (finite
// differences), u(0) = 0 and u_X(L) = 0; the uniform-velocity series moves the
// middle of the bar at V until the wave from the fixed end arrives.
TEST(VibratingBar, SolutionsMeetTheWaveEquationAndBoundaries) {
  const VibratingBar bar{1.0, 100.0};
  // Steps with truncation (omega dt)^2 / 12 and (k d)^2 / 12 below 1e-8.
  const double V = 0.1, X = 0.37, t = 0.0031, d = 1e-4, dt = 1e-6;
  auto u = [&](double x, double s) { return bar.first_mode_displacement(V, x, s); };
  const double u_tt = (u(X, t + dt) - 2 * u(X, t) + u(X, t - dt)) / (dt * dt);
  const double u_xx = (u(X + d, t) - 2 * u(X, t) + u(X - d, t)) / (d * d);
  EXPECT_NEAR(u_tt, bar.wave_speed * bar.wave_speed * u_xx, 1e-5 * std::abs(u_tt));
  EXPECT_EQ(u(0.0, t), 0.0);
  EXPECT_NEAR((u(bar.length, t) - u(bar.length - d, t)) / d, 0.0, 1e-3 * V / bar.frequency(1) * bar.wavenumber(1));
  EXPECT_NEAR(bar.period(1), 4.0 * bar.length / bar.wave_speed, 1e-15);
  // At t = 0.2 L / c the fixed end's wave has reached X = 0.2 L only.
  const double early = 0.2 * bar.length / bar.wave_speed;
  EXPECT_NEAR(bar.uniform_velocity_displacement(V, 0.6, early, 4000) / (V * early), 1.0, 2e-3);
}

#ifdef MPMVV_HAVE_SUNDIALS
// KINSOL solves a small system to its tolerance and reports when it cannot.
TEST(Kinsol, SolvesASystemAndReportsFailure) {
  const NonlinearSolution s = solve_nonlinear(
      [](const std::vector<double>& u, std::vector<double>& f) {
        f[0] = u[0] * u[0] + u[1] * u[1] - 1.0;
        f[1] = u[0] - u[1];
      },
      {1.0, 0.5}, 1e-12);
  EXPECT_NEAR(s.u[0], std::sqrt(0.5), 1e-11);
  EXPECT_NEAR(s.u[1], std::sqrt(0.5), 1e-11);
  EXPECT_LE(s.residual_norm, 1e-12);
  EXPECT_THROW(solve_nonlinear([](const std::vector<double>& u, std::vector<double>& f) { f[0] = u[0] * u[0] + 1.0; },
                               {0.3}, 1e-12),
               SundialsError);
}

// The layered bar (soft against stiff): with equal layers its frequency is the
// one-layer bar's pi c / 2L; with a soft second layer its first mode meets
// the wave equation in each layer, u(0) = 0, continuity of u and of the
// traction M u_X at the interface, and u_X(L) = 0; the frequency is the
// first root (nothing below it changes sign).
TEST(LayeredBar, FirstModeMeetsTheInterfaceAndEndConditions) {
  const double M = 2.79e11, rho = 7850.0;
  const LayeredBar equal{0.5, 0.5, M, M, rho, rho};
  EXPECT_NEAR(equal.first_frequency() / (pi * std::sqrt(M / rho) / 2.0), 1.0, 1e-13);
  for (const double ratio : {0.1, 1e-2, 1e-4, 30.0}) {
    const LayeredBar bar{0.4, 0.6, M, ratio * M, rho, rho};
    const double omega = bar.first_frequency();
    EXPECT_LT(std::abs(bar.frequency_residual(omega)), 1e-13) << ratio;
    for (int k = 1; k < 1000; ++k) EXPECT_LT(bar.frequency_residual(omega * k / 1000.0), 0.0) << ratio;
    const LayeredBarMotion motion{bar, omega, 1.0};
    const double d = 1e-6, L1 = bar.length_1, L = bar.length();
    auto slope = [&](double a, double b) { return (motion.mode(b) - motion.mode(a)) / (b - a); };
    EXPECT_EQ(motion.mode(0.0), 0.0);
    const double scale = std::abs(slope(L1 + d, L1 + 2 * d)) + std::abs(slope(L1 - 2 * d, L1 - d));
    EXPECT_NEAR(motion.mode(L1 - 1e-12), motion.mode(L1), 1e-9 * std::abs(motion.mode(L1))) << ratio;
    EXPECT_NEAR(bar.modulus_1 * slope(L1 - d, L1), bar.modulus_2 * slope(L1, L1 + d), 1e-4 * bar.modulus_1 * scale)
        << ratio;
    EXPECT_NEAR(slope(L - d, L), 0.0, 1e-4 * scale) << ratio;
    // u_tt = c^2 u_XX in the second layer, where u = mode(X) sin(omega t).
    const double X = 0.8, h = 1e-4;
    const double u_xx = (motion.mode(X + h) - 2 * motion.mode(X) + motion.mode(X - h)) / (h * h);
    EXPECT_NEAR(-omega * omega * motion.mode(X), bar.wave_speed_2() * bar.wave_speed_2() * u_xx,
                1e-5 * omega * omega * std::abs(motion.mode(X)))
        << ratio;
  }
  EXPECT_THROW((LayeredBar{0.5, 0.5, M, -M, rho, rho}.first_frequency()), std::invalid_argument);
}

// The neo-Hookean bar: at vanishing stretch it has the small-strain stiffness
// and Poisson contraction of its plane (E / (1 - nu^2), nu / (1 - nu)) or 3D
// (E, nu) form; at 50 % tension and compression the lateral stress is zero
// at the root and the stress has the sign of the stretch.
TEST(Uniaxial, NeoHookeanBarLimitsAndLargeStretch) {
  const double lambda = 577.0, mu = 385.0;
  const NeoHookeanBar bar{lambda, mu};
  const double E = mu * (3 * lambda + 2 * mu) / (lambda + mu), nu = lambda / (2 * (lambda + mu));
  const double eps = 1e-6;
  const NeoHookeanBar::State ps = bar.plane_strain(1.0 + eps);
  EXPECT_NEAR(ps.axial_stress / eps, E / (1 - nu * nu), 1e-4 * E);
  EXPECT_NEAR((ps.lateral_stretch - 1.0) / eps, -nu / (1 - nu), 1e-4);
  const NeoHookeanBar::State us = bar.uniaxial_stress(1.0 + eps);
  EXPECT_NEAR(us.axial_stress / eps, E, 1e-4 * E);
  EXPECT_NEAR((us.lateral_stretch - 1.0) / eps, -nu, 1e-4);
  for (double stretch : {1.5, 0.5}) {
    const NeoHookeanBar::State s = bar.plane_strain(stretch);
    const double J = stretch * s.lateral_stretch;
    const double sigma_yy = lambda * std::log(J) / J + mu / J * (s.lateral_stretch * s.lateral_stretch - 1.0);
    EXPECT_LT(std::abs(sigma_yy), 1e-12 * mu) << stretch;
    EXPECT_GT(s.axial_stress * (stretch - 1.0), 0.0) << stretch;
  }
}
#endif
