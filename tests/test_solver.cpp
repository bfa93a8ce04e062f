// The explicit MPM step on small models built by hand
// (002_c3305cb8b1bc1490.txt section 1.5): momentum conservation, two
// materials, a rigid rotation, repeatable threads, what make_stepper refuses.
#include <gtest/gtest.h>

#include "solver_models.hpp"
#include "support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "solver/explicit_stepper.hpp"
#include "solver/io/state_archive.hpp"
#include "solver/parallel.hpp"
#include "solver/domain_angle.hpp"
#include "solver/domain_corners.hpp"
#include <map>
#include "solver/shape/cpdi.hpp"
#include "solver/split.hpp"
#include "solver/time_loop.hpp"

namespace {

using mpmvv::testing::scientific;
using namespace mpmvv::testing::solver_models;  // the models and the solver's names they use

// ---------------------------------------------------------------- momentum

// sum_p m_p v_p after 20 steps without body force, relative to sum_p m_p |v_p|.
double momentum_change(Method method, Scheme scheme,
                       mpmvv::Formulation formulation = mpmvv::Formulation::updated) {
  Model model = disk_model(method);
  shear_and_stretch(model);
  const Vec2 before = total_momentum(model.particles);
  const double scale = total_momentum_magnitude(model.particles);
  const double dt = stable_step(model);
  SolverOptions options{method, scheme};
  options.formulation = formulation;
  auto stepper = mpmvv::make_stepper(std::move(model), options, MaterialModel{kSolid}, nullptr);
  advance(*stepper, 20, dt);
  const Particles& P = stepper->model().particles;
  // The body deforms, so conservation is not the trivial result of rest.
  double largest_stress = 0.0;
  for (const Mat2& s : P.stress) largest_stress = std::max(largest_stress, s.norm());
  EXPECT_GT(largest_stress, 1e-3 * kSolid.mu);
  return (total_momentum(P) - before).norm() / scale;
}

// With no body force and the body away from the walls, sum_p m_p v_p does not
// change: the internal forces sum to zero over the nodes (the gradients sum
// to zero, eq. 1.70) and the velocity update uses the weights that made the
// node masses. Every method and scheme but CPDI with USF (disabled below).
TEST(Solver, MomentumIsConservedWithoutExternalForce) {
  for (Method method : kMethods)
    for (Scheme scheme : kSchemes) {
      if ((method == Method::cpdi || method == Method::cpdi_exact) && scheme == Scheme::usf) continue;
      SCOPED_TRACE(label(method, scheme));
      const double change = momentum_change(method, scheme);
      RecordProperty("momentum_change_" + label(method, scheme), scientific(change));
      // Measured 6.3e-16 to 1.3e-15 relative: round-off of the node sums.
      // 1e-12 leaves a wide margin and still catches a lost force.
      EXPECT_LT(change, 1e-12);
    }
}

// CPDI with USF conserves momentum: the step maps mass and momentum with the
// domains of F_n, advances F, and must still map forces and read velocities
// back with the domains of F_n (it keeps a copy), or sum_p m_p S_gp no longer
// equals m_g. Before that copy the change was 6.9e-7 relative after 20 steps;
// with it, round-off like every other method and scheme.
TEST(Solver, CpdiUsfConservesMomentum) {
  EXPECT_LT(momentum_change(Method::cpdi, Scheme::usf), 1e-12);
}

// The total Lagrangian formulation (gimp, every scheme) conserves momentum
// like the others: its node masses are the reference weights' and its forces
// sum to zero over the nodes (the reference gradients do).
TEST(Solver, TotalLagrangianConservesMomentum) {
  for (Scheme scheme : kSchemes) {
    SCOPED_TRACE(to_string(scheme));
    EXPECT_LT(momentum_change(Method::gimp, scheme, mpmvv::Formulation::total), 1e-12);
  }
}

// The total Lagrangian formulation takes what its reference grid can do and
// says what it cannot: split domains, r-z.
TEST(Solver, TotalLagrangianRefusesWhatItCannotDo) {
  // Reference domains never deform: splitting them serves nothing.
  SolverOptions split{Method::cpdi, Scheme::usl};
  split.formulation = mpmvv::Formulation::total;
  split.split_domains_beyond = 1.0;
  EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::cpdi), split, MaterialModel{kSolid}, nullptr),
               std::invalid_argument);
  for (Method method : {Method::linear, Method::gimp, Method::cpdi, Method::cpdi_exact}) {
    SolverOptions options{method, Scheme::usl};
    options.formulation = mpmvv::Formulation::total;
    EXPECT_NO_THROW(mpmvv::make_stepper(disk_model(method), options, MaterialModel{kSolid}, nullptr))
        << to_string(method);
  }
  SolverOptions rz{Method::gimp, Scheme::usl};
  rz.formulation = mpmvv::Formulation::total;
  rz.geometry = mpmvv::Geometry::axisymmetric;
  EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::gimp), rz, MaterialModel{kSolid}, nullptr),
               std::invalid_argument);
}

// Two materials in one body (SceneStages::second_material): particles from
// second_material_from on take the second. The disk stretched uniformly, its
// second half twice as stiff: after a step of a nanosecond (F unchanged to
// round-off) each half's stress is its own material's, the monitors' strain
// energy sums both halves' stored energies, and momentum is conserved over a
// hundred steps. A second material of another kind, or one holding no
// particle or every one, is refused.
TEST(Solver, TwoMaterialsEachStressTheirParticles) {
  const NeoHookean stiff{2.0 * kSolid.lambda, 2.0 * kSolid.mu};
  const Mat2 F = (Mat2() << 1.01, 0.002, 0.0, 0.995).finished();
  for (Method method : {Method::linear, Method::cpdi}) {
    SCOPED_TRACE(to_string(method));
    Model model = disk_model(method);
    Particles& P = model.particles;
    const std::size_t n = P.size(), half = n / 2;
    double energy = 0.0;
    for (std::size_t p = 0; p < n; ++p) {
      P.deformation_gradient[p] = F;
      P.volume[p] = mpmvv::determinant(F) * P.reference_volume[p];
      energy += P.reference_volume[p] * (p < half ? kSolid : stiff).energy_density(F, 1.0);
    }
    mpmvv::SceneStages stages;
    stages.second_material = MaterialModel{stiff};
    stages.second_material_from = half;
    auto stepper = mpmvv::make_stepper(model, SolverOptions{method, Scheme::usl}, kSolid, stages);
    EXPECT_NEAR(stepper->monitors().strain / energy, 1.0, 1e-14);
    stepper->step(0.0, 1e-9, 0.5e-9);
    const Particles& Q = stepper->model().particles;
    for (const std::size_t p : {std::size_t(0), half - 1, half, n - 1}) {
      const Mat2 expected = (p < half ? kSolid : stiff).cauchy_stress(F);
      EXPECT_LT((Q.stress[p] - expected).norm(), 1e-9 * expected.norm()) << p;
    }
    EXPECT_LT((Q.stress[half] - 2.0 * Q.stress[half - 1]).norm(), 1e-9 * Q.stress[half].norm());
    Model moving = disk_model(method);
    shear_and_stretch(moving);
    const Vec2 before = total_momentum(moving.particles);
    const double scale = total_momentum_magnitude(moving.particles);
    auto mover = mpmvv::make_stepper(moving, SolverOptions{method, Scheme::usl}, kSolid, stages);
    advance(*mover, 20, stable_step(moving) / std::sqrt(2.0));  // the stiff half's waves are sqrt 2 faster
    EXPECT_LT((total_momentum(mover->model().particles) - before).norm() / scale, 1e-12);
  }
  mpmvv::SceneStages other;
  other.second_material = MaterialModel{mpmvv::LinearElastic{577.0, 385.0}};
  other.second_material_from = 10;
  EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::cpdi), SolverOptions{}, kSolid, other), std::invalid_argument);
  for (std::size_t from : {std::size_t(0), disk_model(Method::cpdi).particles.size()}) {
    mpmvv::SceneStages empty;
    empty.second_material = MaterialModel{kSolid};
    empty.second_material_from = from;
    EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::cpdi), SolverOptions{}, kSolid, empty), std::invalid_argument)
        << from;
  }
}

// ---------------------------------------------------------------- rigid rotation

constexpr double kSpin = 0.5;  // omega [rad/s]

// The centripetal force per unit mass -omega^2 x that makes a stress-free
// rigid rotation an exact solution of the balance of momentum.
class CentripetalForce final : public mpmvv::BodyForce {
 public:
  void evaluate(double, const Particles& P, std::vector<Vec2>& b) const override {
    for (std::size_t p = 0; p < P.size(); ++p) b[p] = -kSpin * kSpin * P.position[p];
  }
};

struct RotationResult {
  double volume_change;        // (sum V_p - sum V_p0) / sum V_p0
  double largest_stress;       // max_p |sigma_p| / mu
  double interior_stress;      // the same over particles with reference radius < 0.5 m
  double interior_mean_J;      // mean J - 1 over those particles
  double mean_angle;           // mean angle turned [rad]
};

// A quarter turn of the disk spinning at omega under the centripetal force.
RotationResult quarter_turn(Method method, Scheme scheme, const NeoHookean& solid,
                            int cells = 32) {
  Model model = disk_model(method, cells);
  for (std::size_t p = 0; p < model.particles.size(); ++p) {
    const Vec2 x = model.particles.position[p];
    model.particles.velocity[p] = kSpin * Vec2(-x.y(), x.x());
  }
  const double duration = 0.5 * std::numbers::pi / kSpin;
  const int steps = int(std::ceil(duration / stable_step(model)));
  auto stepper = mpmvv::make_stepper(std::move(model), SolverOptions{method, scheme}, MaterialModel{solid},
                                     std::make_shared<CentripetalForce>());
  advance(*stepper, steps, duration / steps);

  const Particles& P = stepper->model().particles;
  RotationResult r{0.0, 0.0, 0.0, 0.0, 0.0};
  double volume = 0.0, reference_volume = 0.0;
  int interior = 0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    volume += P.volume[p];
    reference_volume += P.reference_volume[p];
    const double stress = P.stress[p].norm() / kSolid.mu;
    r.largest_stress = std::max(r.largest_stress, stress);
    const Vec2 X = P.reference_position[p], x = P.position[p];
    r.mean_angle += std::atan2(X.x() * x.y() - X.y() * x.x(), X.dot(x)) / double(P.size());
    if (X.norm() < 0.5) {
      ++interior;
      r.interior_stress = std::max(r.interior_stress, stress);
      r.interior_mean_J += mpmvv::determinant(P.deformation_gradient[p]) - 1.0;
    }
  }
  r.volume_change = volume / reference_volume - 1.0;
  r.interior_mean_J /= interior;
  return r;
}

// A material without stiffness: the particles move under the centripetal
// force alone, and F only records their motion.
const NeoHookean kNoStiffness{0.0, 0.0};

// With update-stress-last (USL, MUSL) the forward-Euler increment
// I + dt L (eq. 1.74) is the exact gradient of the position update (eq. 1.76),
// so a stress-free body turning a quarter turn keeps J = 1 in its interior;
// the disk turns within 2% of pi/2 (the lag is the smoothing of the grid
// velocity).
TEST(RigidRotation, ForwardEulerIncrementFollowsTheParticleMotion) {
  for (Method method : kMethods)
    for (Scheme scheme : {Scheme::usl, Scheme::musl}) {
      SCOPED_TRACE(label(method, scheme));
      const RotationResult r = quarter_turn(method, scheme, kNoStiffness);
      RecordProperty("interior_mean_J_minus_1_" + label(method, scheme), scientific(r.interior_mean_J));
      // Measured +7.9e-5 (linear), +8.3e-5 (gimp), +1.6e-3 (cpdi) under USL and
      // +9.4e-5, +1.1e-4, +1.7e-3 under MUSL. (A Cayley "midpoint" increment
      // applied to this L drifts to -2.5e-2: it is not the gradient of the
      // position update, which is why the solver has only eq. 1.74.)
      EXPECT_LT(std::abs(r.interior_mean_J), 5e-3);
      // Measured 1.5528-1.5577 rad against pi/2 = 1.5708: a lag of 0.8-1.1%.
      EXPECT_NEAR(r.mean_angle, 0.5 * std::numbers::pi, 0.02 * 0.5 * std::numbers::pi);
    }
}

// An elastic disk in rigid rotation is exactly stress-free and keeps its
// volume. The computed one keeps its volume within 4e-3 and its spurious
// stress (from the grid velocity near the free surface, where the particles
// do not surround a node, spreading inward as waves) is a discretisation
// error: it falls when the cells are halved, for every method and scheme.
TEST(RigidRotation, ElasticDiskSpuriousStressFallsUnderRefinement) {
  for (Method method : kMethods)
    for (Scheme scheme : kSchemes) {
      SCOPED_TRACE(label(method, scheme));
      const RotationResult coarse = quarter_turn(method, scheme, kSolid, 32);
      const RotationResult fine = quarter_turn(method, scheme, kSolid, 64);
      const std::string name = label(method, scheme);
      RecordProperty("volume_change_32_" + name, scientific(coarse.volume_change));
      RecordProperty("largest_stress_over_mu_32_" + name, scientific(coarse.largest_stress));
      RecordProperty("interior_stress_over_mu_32_" + name, scientific(coarse.interior_stress));
      RecordProperty("interior_stress_over_mu_64_" + name, scientific(fine.interior_stress));
      // Measured |dV/V| at 32 cells: 5.7e-5 to 1.7e-3.
      EXPECT_LT(std::abs(coarse.volume_change), 4e-3);
      // Measured max |sigma| / mu at 32 cells: 0.06 (gimp, cpdi USL) to 0.72
      // (linear USL, one particle crossing a cell edge).
      EXPECT_LT(coarse.largest_stress, 1.0);
      // Measured interior ratios fine / coarse: 0.23 to 0.51.
      EXPECT_LT(fine.interior_stress, 0.7 * coarse.interior_stress);
    }
}

// ---------------------------------------------------------------- threads

std::vector<Vec2> positions_after_steps(int threads) {
  mpmvv::set_threads(threads);
  Model model = disk_model(Method::cpdi);
  for (std::size_t p = 0; p < model.particles.size(); ++p) {
    const Vec2 x = model.particles.position[p];
    model.particles.velocity[p] = Vec2(0.1 * std::sin(3.0 * x.y()), 0.05 * x.x() * x.x());
  }
  const double dt = stable_step(model);
  auto stepper = mpmvv::make_stepper(std::move(model), SolverOptions{Method::cpdi, Scheme::usl},
                                     MaterialModel{kSolid}, nullptr);
  advance(*stepper, 20, dt);
  return stepper->model().particles.position;
}

// The same thread count gives bit-for-bit the same run; one and two threads
// differ only by the order of the node sums.
TEST(Threads, RunsAreRepeatable) {
  const int default_threads = mpmvv::max_threads();
  mpmvv::set_threads(2);
  const bool two_threads = mpmvv::max_threads() == 2;
  mpmvv::set_threads(default_threads);
  if (!two_threads) GTEST_SKIP() << "built without OpenMP";
  const std::vector<Vec2> first = positions_after_steps(2), second = positions_after_steps(2);
  const std::vector<Vec2> single = positions_after_steps(1);
  mpmvv::set_threads(default_threads);
  ASSERT_EQ(first.size(), second.size());
  ASSERT_EQ(first.size(), single.size());
  double largest = 0.0;
  for (std::size_t p = 0; p < first.size(); ++p) {
    EXPECT_EQ(first[p].x(), second[p].x()) << "particle " << p;
    EXPECT_EQ(first[p].y(), second[p].y()) << "particle " << p;
    largest = std::max(largest, (first[p] - single[p]).norm() / first[p].norm());
  }
  RecordProperty("one_versus_two_threads", scientific(largest));
  // Measured largest relative difference 0 to a few 1e-16: round-off of the
  // reordered sums.
  EXPECT_LT(largest, 1e-12);
}

// Sums over a parallel loop (energies, work ledgers, error norms) come out
// with the same bits whichever thread finishes first: with four threads the
// threads' sums are added in thread order, the sum a serial loop over the
// same static blocks gives. Terms of many magnitudes make any other order
// show in the last bits.
TEST(Threads, SumsAreAddedInThreadOrder) {
  const int default_threads = mpmvv::max_threads();
  mpmvv::set_threads(4);
  const bool four_threads = mpmvv::max_threads() == 4;
  if (!four_threads) {
    mpmvv::set_threads(default_threads);
    GTEST_SKIP() << "built without OpenMP";
  }
  const std::size_t n = 4003;
  std::vector<double> term(n);
  for (std::size_t p = 0; p < n; ++p) term[p] = std::pow(10.0, double(p % 17) - 8.0) * (1.0 + 1e-3 * double(p));
  auto parallel_sum = [&] {
    mpmvv::ThreadOrderedSums<1> sums;
#pragma omp parallel num_threads(4)
    {
      double own = 0.0;
#pragma omp for schedule(static)
      for (std::size_t p = 0; p < n; ++p) own += term[p];
      sums.keep({own});
    }
    return sums.total()[0];
  };
  // libgomp's static split: the first n % 4 threads take one more.
  double expected = 0.0;
  std::size_t first = 0;
  for (std::size_t t = 0; t < 4; ++t) {
    const std::size_t count = n / 4 + (t < n % 4 ? 1 : 0);
    double own = 0.0;
    for (std::size_t p = first; p < first + count; ++p) own += term[p];
    expected += own;
    first += count;
  }
  for (int repeat = 0; repeat < 200; ++repeat) ASSERT_EQ(parallel_sum(), expected) << "repeat " << repeat;
  mpmvv::set_threads(default_threads);
}

// A method that needs particle domains refuses particles without them.
TEST(Solver, MakeStepperRefusesMissingParticleDomains) {
  for (Method method : {Method::gimp, Method::cpdi}) {
    Model model = disk_model(Method::linear);
    EXPECT_THROW(mpmvv::make_stepper(std::move(model), SolverOptions{method, Scheme::usl},
                                     MaterialModel{kSolid}, nullptr),
                 std::invalid_argument)
        << to_string(method);
  }
}


}  // namespace
