// How far a static scene's end still is from its static state
// (tools/app/scene/settling.hpp), the measurements the report and the gate compare
// errors with: the relaxation's estimate is exact for a motion that decays at
// the slowest rate of the damped lowest mode; a run stopped sooner has further
// to go; implicit load steps report the Newton correction left, which a looser
// tolerance makes larger.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "run_scene.hpp"
#include "tools/app/scene/settling.hpp"

namespace {

using mpmvv::Mat2;
using mpmvv::Particles;
using mpmvv::Vec2;
using mpmvv::app::SettlingBody;
using mpmvv::app::SettlingWatch;

// Particles at x = X + A_p exp(-s t), F = I + B_p exp(-s t).
struct Decay {
  double rate;
  std::vector<Vec2> A = {Vec2(1.0, -2.0), Vec2(0.5, 0.0), Vec2(0.0, 3.0)};
  std::vector<Mat2> B = {Mat2{{0.1, 0.2}, {0.0, -0.1}}, Mat2{{0.0, 0.0}, {0.3, 0.0}}, Mat2{{0.05, 0.0}, {0.0, 0.05}}};
  std::vector<double> volume = {1.0, 2.0, 0.5};

  void at(double t, Particles& P) const {
    P.resize(A.size());
    for (std::size_t p = 0; p < A.size(); ++p) {
      P.reference_volume[p] = volume[p];
      P.position[p] = Vec2(double(p), 1.0) + A[p] * std::exp(-rate * t);
      P.deformation_gradient[p] = Mat2::Identity() + B[p] * std::exp(-rate * t);
    }
  }
  // The volume-weighted RMS of what is still to go at t.
  std::pair<double, double> left(double t) const {
    double moved = 0.0, strained = 0.0, total = 0.0;
    for (std::size_t p = 0; p < A.size(); ++p) {
      const Mat2 e = 0.5 * (B[p] + B[p].transpose());
      moved += volume[p] * A[p].squaredNorm();
      strained += volume[p] * e.squaredNorm();
      total += volume[p];
    }
    return {std::sqrt(moved / total) * std::exp(-rate * t), std::sqrt(strained / total) * std::exp(-rate * t)};
  }
};

mpmvv::Settling relax(const SettlingBody& body, const Decay& decay, double end) {
  SettlingWatch watch(body, end, true);
  Particles P;
  for (int k = 0; k <= 400; ++k) {
    const double t = end * k / 400.0;
    decay.at(t, P);
    watch.observe(t, P);
  }
  return watch.relaxation(end, P);
}

double settling(const mpmvv::h5::File& f, const std::string& name) {
  return f.root().open_group("measurements").attribute_double(name);
}

// Both settling measurements of `less` are positive, and those of `more` over
// `factor` times them.
void expect_further(const mpmvv::h5::File& less, const mpmvv::h5::File& more, double factor) {
  for (const char* name : {"settling_displacement", "settling_strain"}) {
    EXPECT_GT(settling(less, name), 0.0) << name;
    EXPECT_GT(settling(more, name), factor * settling(less, name)) << name;
  }
}

}  // namespace

// Critical damping (zeta = 2 omega_1) decays at omega_1, overdamping at the
// slow root omega_1 (r - sqrt(r^2 - 1)), underdamping at zeta / 2; a motion
// decaying at that rate is estimated exactly. Without damping nothing settles.
TEST(Settling, RelaxationEstimateIsExactForTheSlowestDecay) {
  const double omega = 2.0, end = 3.0;
  for (const double ratio : {1.0, 2.5, 0.4}) {
    const double zeta = 2.0 * ratio * omega;
    const double rate = ratio >= 1.0 ? omega * (ratio - std::sqrt(ratio * ratio - 1.0)) : 0.5 * zeta;
    const Decay decay{rate};
    const auto s = relax({omega, 1.0, zeta}, decay, end);
    const auto [displacement, strain] = decay.left(end);
    EXPECT_NEAR(s.displacement, displacement, 1e-9 * displacement) << ratio;
    EXPECT_NEAR(s.strain, strain, 1e-9 * strain) << ratio;
    // A motion that decays twice as fast is over-estimated, not under.
    const Decay faster{2.0 * rate};
    EXPECT_GT(relax({omega, 1.0, zeta}, faster, end).displacement, faster.left(end).first) << ratio;
  }
  EXPECT_TRUE(std::isnan(relax({omega, 1.0, 0.0}, Decay{1.0}, end).displacement));
}

// The steel bar's dynamic relaxation (uGIMP, 22 cells) stopped at the earliest
// end its keys allow, half a ramp after the ramp, has further to go than at
// its default end: measured 4.0e-13 m and 4.9e-18 m, strains 4.4e-11 and
// 1.4e-16 (the grip moves 0.86 um).
TEST(Settling, ARelaxationStoppedSoonerHasFurtherToGo) {
  const auto full = mpmvv::testing::run_scene("uniaxial-tension.toml", "settling-full", "--set method=gimp");
  const auto early = mpmvv::testing::run_scene("uniaxial-tension.toml", "settling-early",
                                               "--set method=gimp --set end_time=7.1e-5");
  expect_further(full, early, 1e4);
  EXPECT_LT(settling(full, "settling_displacement"), 1e-12);
}

#ifdef MPMVV_HAVE_SUNDIALS
// Implicit load steps end where the Newton iteration stops: a looser tolerance
// leaves a larger correction still to make. Measured (CPDI, 22 cells) 2.2e-14 m
// and strain 4.1e-13 at the default 1e-8; 6.0e-12 m and 7.2e-10 at 1e-4.
TEST(Settling, ImplicitStepsReportTheNewtonCorrectionLeft) {
  const auto tight = mpmvv::testing::run_scene("uniaxial-tension.toml", "settling-tight", "--set solver=implicit");
  const auto loose = mpmvv::testing::run_scene("uniaxial-tension.toml", "settling-loose",
                                               "--set solver=implicit --set newton_tolerance=1e-4");
  expect_further(tight, loose, 100.0);
}
#endif
