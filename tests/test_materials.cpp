// Materials by their properties: stress-free reference state, objectivity,
// closed forms under simple shear, the small-strain moduli, and the wave
// modulus the time step relies on (000_1dbcb8acb6dddab9.txt eqs. 2.2, 2.18).
#include <gtest/gtest.h>

#include "support.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "solver/material/mooney_rivlin.hpp"
#include "solver/material/neo_hookean.hpp"

namespace {

using mpmvv::Mat2;
using mpmvv::MooneyRivlin;
using mpmvv::NeoHookean;

// The report's neo-Hookean solid (eq. 2.2) and a Mooney-Rivlin solid of
// comparable stiffness: shear modulus 2 (c1 + c2) = 400 Pa, K = 800 Pa.
const NeoHookean kNeoHookean{577.0, 385.0};
const MooneyRivlin kMooneyRivlin{150.0, 50.0, 800.0};
const MooneyRivlin kMooneyRivlinWithoutC2{200.0, 0.0, 800.0};

using mpmvv::testing::rotation;
using mpmvv::testing::simple_shear;

// Random F with det F >= 0.3 and entries of order one.
Mat2 random_deformation(std::mt19937& rng) { return mpmvv::testing::random_deformation(rng, 0.7, 0.3); }

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }

std::string show(const Mat2& a) {
  std::ostringstream text;
  text << "[" << a(0, 0) << " " << a(0, 1) << "; " << a(1, 0) << " " << a(1, 1) << "]";
  return text.str();
}

// The largest rho c^2 (rho = rho_0 / J) over in-plane directions and
// polarisations: the largest eigenvalue of the spatial acoustic tensor
//   Q_ik(n) = (1/J) dP_iJ/dF_kL F_jJ F_lL n_j n_l,
// with dP/dF by central differences of P = J sigma F^-T and n sampled every
// quarter degree. The differences carry a relative error of about 1e-9.
template <class Material>
double largest_acoustic_modulus(const Material& m, const Mat2& F) {
  auto first_piola = [&](const Mat2& G) {
    return Mat2(mpmvv::determinant(G) * m.cauchy_stress(G) * mpmvv::inverse(G).transpose());
  };
  const double J = mpmvv::determinant(F);
  double A[2][2][2][2];  // A[i][I][k][L] = dP_iI / dF_kL
  const double step = 1e-6;
  for (int k = 0; k < 2; ++k)
    for (int L = 0; L < 2; ++L) {
      Mat2 plus = F, minus = F;
      plus(k, L) += step;
      minus(k, L) -= step;
      const Mat2 dP = (first_piola(plus) - first_piola(minus)) / (2.0 * step);
      for (int i = 0; i < 2; ++i)
        for (int I = 0; I < 2; ++I) A[i][I][k][L] = dP(i, I);
    }
  double largest = 0.0;
  for (int d = 0; d < 720; ++d) {
    const double theta = d * std::numbers::pi / 720.0;
    const mpmvv::Vec2 n(std::cos(theta), std::sin(theta));
    const mpmvv::Vec2 material_n = F.transpose() * n;  // F_jJ n_j
    Mat2 acoustic = Mat2::Zero();
    for (int i = 0; i < 2; ++i)
      for (int k = 0; k < 2; ++k)
        for (int I = 0; I < 2; ++I)
          for (int L = 0; L < 2; ++L) acoustic(i, k) += A[i][I][k][L] * material_n[I] * material_n[L] / J;
    largest = std::max(largest, mpmvv::largest_principal(Mat2(0.5 * (acoustic + acoustic.transpose()))));
  }
  return largest;
}

// wave_modulus / largest rho c^2, the smallest over random F with det F in
// [min_J, max_J]: at least one if the wave modulus is a bound.
template <class Material>
double tightest_wave_modulus_ratio(const Material& m, double min_J, double max_J, unsigned seed) {
  std::mt19937 rng(seed);
  double tightest = 1e300;
  int sampled = 0;
  while (sampled < 200) {
    const Mat2 F = random_deformation(rng);
    const double J = mpmvv::determinant(F);
    if (J < min_J || J > max_J) continue;
    ++sampled;
    tightest = std::min(tightest, m.wave_modulus(F, m.cauchy_stress(F)) / largest_acoustic_modulus(m, F));
  }
  return tightest;
}

template <class Material>
class MaterialTest : public ::testing::Test {
 public:
  static Material material();
  static double modulus() { return material().p_wave_modulus(); }
};
template <>
NeoHookean MaterialTest<NeoHookean>::material() { return kNeoHookean; }
template <>
MooneyRivlin MaterialTest<MooneyRivlin>::material() { return kMooneyRivlin; }

using Materials = ::testing::Types<NeoHookean, MooneyRivlin>;
TYPED_TEST_SUITE(MaterialTest, Materials);

// sigma(I) = 0: the reference state is stress-free.
TYPED_TEST(MaterialTest, StressFreeAtIdentity) {
  const Mat2 sigma = TestFixture::material().cauchy_stress(Mat2(Mat2::Identity()));
  // A few terms of order the modulus cancel exactly in exact arithmetic.
  EXPECT_LT(sigma.norm(), 1e-12 * TestFixture::modulus()) << show(sigma);
}

// sigma(Q F) = Q sigma(F) Q^T for rotations Q and random F with det F > 0, and
// sigma is symmetric.
TYPED_TEST(MaterialTest, Objective) {
  const TypeParam m = TestFixture::material();
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> angle(-3.14159, 3.14159);
  for (int k = 0; k < 200; ++k) {
    const Mat2 F = random_deformation(rng), Q = rotation(angle(rng));
    const Mat2 sigma = m.cauchy_stress(F);
    const Mat2 rotated = m.cauchy_stress(Mat2(Q * F));
    // Both sides are the same formula evaluated in two bases: round-off of a
    // few 1e-16 relative to the stress (or to the modulus when the stress is small).
    const double scale = sigma.norm() + 1e-3 * TestFixture::modulus();
    EXPECT_LT((rotated - Q * sigma * Q.transpose()).norm(), 1e-10 * scale) << "F = " << show(F);
    EXPECT_LT(std::abs(sigma(0, 1) - sigma(1, 0)), 1e-12 * scale) << "F = " << show(F);
  }
}

// Under uniaxial strain F = diag(1 + e, 1) the small-strain stiffness
// sigma_xx / e is the P-wave modulus the time step starts from.
TYPED_TEST(MaterialTest, UniaxialStrainStiffnessIsPWaveModulus) {
  const TypeParam m = TestFixture::material();
  const double e = 1e-7;
  Mat2 F = Mat2::Identity();
  F(0, 0) += e;
  const double stiffness = m.cauchy_stress(F)(0, 0) / e;
  // The next term is O(e) relative; the stress itself carries round-off
  // 1e-16 / e = 1e-9 relative. 1e-6 covers both.
  EXPECT_NEAR(stiffness, m.p_wave_modulus(), 1e-6 * m.p_wave_modulus());
}

// ---------------------------------------------------------------- neo-Hookean

// Simple shear F = [1 g; 0 1] has J = 1, so eq. 2.2 gives sigma = mu (B - I):
// sigma_xy = mu g, sigma_xx = mu g^2, sigma_yy = 0.
TEST(NeoHookean, SimpleShearClosedForm) {
  for (double gamma : {1e-3, 0.3, 1.0, 3.0}) {
    const Mat2 sigma = kNeoHookean.cauchy_stress(simple_shear(gamma));
    const double mu = kNeoHookean.mu;
    // J = 1 exactly, ln J = 0 exactly: the only error is the rounding of B.
    const double tolerance = 1e-13 * mu * (1.0 + gamma * gamma);
    EXPECT_NEAR(sigma(0, 1), mu * gamma, tolerance) << "gamma = " << gamma;
    EXPECT_NEAR(sigma(1, 0), mu * gamma, tolerance) << "gamma = " << gamma;
    EXPECT_NEAR(sigma(0, 0), mu * gamma * gamma, tolerance) << "gamma = " << gamma;
    EXPECT_NEAR(sigma(1, 1), 0.0, tolerance) << "gamma = " << gamma;
  }
}

// Under equal biaxial stretch F = s I the closed form of eq. 2.2 is
// sigma = (lambda ln J + mu (s^2 - 1)) / J I with J = s^2.
TEST(NeoHookean, EqualBiaxialStretchClosedForm) {
  for (double s : {0.8, 0.95, 1.1, 1.5}) {
    const double J = s * s;
    const double expected = (kNeoHookean.lambda * std::log(J) + kNeoHookean.mu * (s * s - 1.0)) / J;
    const Mat2 sigma = kNeoHookean.cauchy_stress(Mat2(s * Mat2::Identity()));
    EXPECT_NEAR(sigma(0, 0), expected, 1e-12 * kNeoHookean.p_wave_modulus()) << "s = " << s;
    EXPECT_NEAR(sigma(1, 1), expected, 1e-12 * kNeoHookean.p_wave_modulus()) << "s = " << s;
    EXPECT_NEAR(sigma(0, 1), 0.0, 1e-12 * kNeoHookean.p_wave_modulus()) << "s = " << s;
  }
}

// The wave modulus bounds rho c^2 over all in-plane directions at any
// state (the bound the neo-Hookean header derives), and is tight: measured
// smallest ratio 1.0000 over 200 random F with det F >= 0.3 (simple shear
// attains it).
TEST(NeoHookean, WaveModulusBoundsTheAcousticTensor) {
  const double tightest = tightest_wave_modulus_ratio(kNeoHookean, 0.3, 1e300, 23);
  // 1e-6 allows for the differences and the sampled directions.
  EXPECT_GE(tightest, 1.0 - 1e-6);
  EXPECT_LT(tightest, 1.01);
}

// At F = I the wave modulus is exactly lambda + 2 mu; under shear it never
// drops below it (the time step cannot grow with deformation).
TEST(NeoHookean, WaveModulusIsPWaveModulusAtRestAndGrowsUnderShear) {
  EXPECT_EQ(kNeoHookean.p_wave_modulus(), kNeoHookean.lambda + 2.0 * kNeoHookean.mu);
  EXPECT_DOUBLE_EQ(kNeoHookean.wave_modulus(Mat2::Identity(), Mat2::Zero()), kNeoHookean.p_wave_modulus());
  for (double gamma : {1e-3, 0.5, 1.0, 3.0}) {
    const Mat2 F = simple_shear(gamma);
    EXPECT_GE(kNeoHookean.wave_modulus(F, kNeoHookean.cauchy_stress(F)), kNeoHookean.p_wave_modulus())
        << "gamma = " << gamma;
  }
}

// The scan's early test (stages.hpp: signal_speed) leaves out a particle only
// below wave_modulus_bound: it must never be below the wave modulus, in
// compression and tension, with and without an out-of-plane stretch, and for
// a negative lambda (the bound takes |mu - lambda x| at both ends).
TEST(NeoHookean, WaveModulusBoundIsAtLeastTheWaveModulus) {
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> stretch(0.3, 3.0);
  for (const mpmvv::NeoHookean& m : {kNeoHookean, mpmvv::NeoHookean{576923.0769230769, 384615.3846153846},
                                     mpmvv::NeoHookean{-100.0, 400.0}}) {
    double tightest = 1e300;
    for (int k = 0; k < 2000; ++k) {
      const Mat2 F = mpmvv::testing::random_deformation(rng, 1.5, 0.1);
      const double F33 = k % 2 ? 1.0 : stretch(rng);
      if (!(mpmvv::determinant(F) * F33 > 0.0)) continue;
      const Mat2 sigma = m.stress(F, F33).in_plane;
      const double exact = m.wave_modulus(F, F33, sigma), bound = m.wave_modulus_bound(F, F33, sigma);
      ASSERT_GE(bound, exact) << "F = " << show(F) << ", F33 = " << F33 << ", lambda = " << m.lambda;
      tightest = std::min(tightest, bound / exact);
    }
    // The bound is tight where J = 1 and the stress has no shear, as at rest.
    EXPECT_DOUBLE_EQ(m.wave_modulus_bound(Mat2::Identity(), 1.0, Mat2::Zero()),
                     m.wave_modulus(Mat2::Identity(), 1.0, Mat2::Zero()));
    EXPECT_LT(tightest, 1.01);
  }
}

// The stress update in lanes (neo_hookean_lanes.hpp) against the scalar
// stress: the same operations but for ln J, so within a few units in the
// last place of the stress's own terms; the same bits from every build and
// for every count (the last few through spare lanes); a J that is not
// positive, finite and normal takes the scalar stress itself.
TEST(NeoHookean, StressInLanesIsTheScalarStress) {
  std::mt19937 rng(43);
  std::vector<Mat2> F;
  for (int k = 0; k < 5000; ++k) F.push_back(mpmvv::testing::random_deformation(rng, 1.5, 0.05));
  F.push_back(Mat2::Identity());
  F.push_back(Mat2{{2.0, 1.0}, {4.0, 2.0}});                     // J = 0
  F.push_back(Mat2{{0.0, 1.0}, {1.0, 0.0}});                     // J = -1
  F.push_back(Mat2{{1e-200, 0.0}, {0.0, 1e-200}});               // J below the normal range
  F.push_back(Mat2{{std::nan(""), 0.0}, {0.0, 1.0}});            // not finite
  F.push_back(Mat2{{1e300, 0.0}, {0.0, 1e300}});                 // J = inf
  const std::size_t n = F.size(), special = 5;
  for (const NeoHookean& m : {kNeoHookean, NeoHookean{576923.0769230769, 384615.3846153846}}) {
    std::vector<Mat2> lanes(n);
    m.cauchy_stress_array(n, F.data(), lanes.data());
    double worst = 0.0;
    for (std::size_t p = 0; p < n; ++p) {
      const Mat2 scalar = m.cauchy_stress(F[p]);
      if (p + special >= n) {
        for (int c = 0; c < 4; ++c)
          EXPECT_EQ(bits(lanes[p](c)), bits(scalar(c))) << "F = " << show(F[p]) << ", entry " << c;
        continue;
      }
      // The scale of each entry's terms: |p| + |mu / J| |B - I|.
      const double J = mpmvv::determinant(F[p]);
      const Mat2 B = F[p] * F[p].transpose();
      const double scale =
          std::abs(m.lambda * std::log(J) / J) + std::abs(m.mu / J) * (B.cwiseAbs().maxCoeff() + 1.0);
      for (int c = 0; c < 4; ++c) worst = std::max(worst, std::abs(lanes[p](c) - scalar(c)) / scale);
    }
    const double epsilon = std::numeric_limits<double>::epsilon();
    RecordProperty("largest_stress_difference_in_epsilon_of_scale", std::to_string(worst / epsilon));
    EXPECT_LE(worst, 4 * epsilon);
    for (mpmvv::LaneBuild build : mpmvv::testing::lane_builds_of_this_cpu()) {
      SCOPED_TRACE(mpmvv::name(build));
      for (std::size_t count : {n, std::size_t(1), std::size_t(7), std::size_t(13)}) {
        std::vector<Mat2> out(count);
        mpmvv::neo_hookean_lane_stress(build, {m.lambda, m.mu}, count, mpmvv::values_of(F.data()),
                                       mpmvv::values_of(out.data()));
        for (std::size_t p = 0; p < std::min(count, n - special); ++p)
          for (int c = 0; c < 4; ++c) ASSERT_EQ(bits(out[p](c)), bits(lanes[p](c))) << "count " << count;
      }
    }
  }
}

// ---------------------------------------------------------------- Mooney-Rivlin

// At small shear sigma_xy / gamma tends to the shear modulus 2 (c1 + c2), with
// and without c2.
TEST(MooneyRivlin, SmallShearModulusIsTwiceC1PlusC2) {
  const double gamma = 1e-6;
  for (const MooneyRivlin& m : {kMooneyRivlin, kMooneyRivlinWithoutC2}) {
    const double modulus = m.cauchy_stress(simple_shear(gamma))(0, 1) / gamma;
    // The next term is O(gamma^2) = 1e-12 relative; the pow(J, -2/3) factors
    // round to 1e-16 relative. 1e-9 leaves margin for both.
    EXPECT_NEAR(modulus, 2.0 * (m.c1 + m.c2), 1e-9 * m.shear_modulus()) << "c2 = " << m.c2;
    EXPECT_DOUBLE_EQ(m.shear_modulus(), 2.0 * (m.c1 + m.c2));
  }
}

// With c2 = 0 and J = 1 the Mooney-Rivlin stress reduces to the isochoric
// neo-Hookean form 2 c1 (B - (I1/3) I), so under simple shear sigma_xy = 2 c1 g
// at any g.
TEST(MooneyRivlin, WithoutC2SimpleShearIsLinearInShear) {
  for (double gamma : {0.1, 1.0, 2.5}) {
    const Mat2 sigma = kMooneyRivlinWithoutC2.cauchy_stress(simple_shear(gamma));
    EXPECT_NEAR(sigma(0, 1), 2.0 * kMooneyRivlinWithoutC2.c1 * gamma, 1e-12 * kMooneyRivlinWithoutC2.c1 * (1 + gamma))
        << "gamma = " << gamma;
  }
}

// The volumetric term K ln J / J is what 000_1dbcb8acb6dddab9.txt eq. 2.18 as
// printed lacks: under equal triaxial stretch it would be the whole stress.
// In plane strain a pure in-plane dilation F = s I has J = s^2 and, with the
// deviatoric part of B = diag(s^2, s^2, 1), the mean in-plane stress
// (sigma_xx + sigma_yy)/2 at small strain is (K + G/3) 2 e.
TEST(MooneyRivlin, SmallInPlaneDilationStiffness) {
  const double e = 1e-7;
  const MooneyRivlin& m = kMooneyRivlin;
  const Mat2 sigma = m.cauchy_stress(Mat2((1.0 + e) * Mat2::Identity()));
  const double expected = (m.bulk_modulus + m.shear_modulus() / 3.0) * 2.0 * e;
  // O(e) relative from the next term, 1e-9 from round-off of ln J.
  EXPECT_NEAR(0.5 * sigma.trace(), expected, 1e-6 * std::abs(expected));
}

// Away from compression (det F >= 1) the Mooney-Rivlin wave modulus bounds
// rho c^2: measured smallest ratio 1.004 over 200 random F.
TEST(MooneyRivlin, WaveModulusBoundsTheAcousticTensorWhenNotCompressed) {
  EXPECT_GE(tightest_wave_modulus_ratio(kMooneyRivlin, 1.0, 1e300, 29), 1.0 - 1e-6);
}

// Under compression the Mooney-Rivlin wave modulus also bounds rho c^2. (Its
// first form, K |1 - ln J| for the volumetric part and I1b for the isochoric
// part, fell short: smallest ratio 0.77 at J = 0.33, 0.995 after the
// volumetric fix, before the isochoric part took the largest stretch.)
TEST(MooneyRivlin, WaveModulusBoundsTheAcousticTensorUnderCompression) {
  EXPECT_GE(tightest_wave_modulus_ratio(kMooneyRivlin, 0.3, 1.0, 31), 1.0 - 1e-6);
}

}  // namespace

// The stored energy of each hyperelastic material is zero at F = I and its
// derivative is the first Piola stress J sigma F^-T (in-plane block, central
// differences of psi at random F, plane strain and with an out-of-plane
// stretch): the energy monitors count the work the stress does.
TEST(StoredEnergy, VanishesAtRestAndDifferentiatesToTheStress) {
  const mpmvv::NeoHookean neo{577.0, 385.0};
  const mpmvv::MooneyRivlin mooney{150.0, 40.0, 850.0};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> d(-0.3, 0.3);
  auto check = [&](const auto& material, const char* name) {
    EXPECT_NEAR(material.energy_density(mpmvv::Mat2(mpmvv::Mat2::Identity()), 1.0), 0.0, 1e-12) << name;
    for (int k = 0; k < 50; ++k) {
      mpmvv::Mat2 F;
      F << 1.0 + d(rng), d(rng), d(rng), 1.0 + d(rng);
      const double F33 = k % 2 ? 1.0 : 1.0 + 0.5 * d(rng);
      const auto s = material.stress(F, F33);
      const double J = mpmvv::determinant(F) * F33;
      const mpmvv::Mat2 P = J * s.in_plane * mpmvv::inverse(F).transpose();
      const double step = 1e-6;
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) {
          mpmvv::Mat2 up = F, down = F;
          up(i, j) += step;
          down(i, j) -= step;
          const double derivative =
              (material.energy_density(up, F33) - material.energy_density(down, F33)) / (2.0 * step);
          EXPECT_NEAR(derivative, P(i, j), 1e-6 * (1.0 + P.norm())) << name << " F = " << F << " F33 = " << F33;
        }
    }
  };
  check(neo, "neo-hookean");
  check(mooney, "mooney-rivlin");
}
