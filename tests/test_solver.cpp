// The explicit MPM step and the time loop on small models built by hand
// (002_c3305cb8b1bc1490.txt section 1.5): momentum conservation, a rigid
// rotation, failures reported as data, repeatable threads, and a time loop
// that lands on its output times within the CFL step.
#include <gtest/gtest.h>

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

using mpmvv::Mat2;
using mpmvv::MaterialModel;
using mpmvv::Method;
using mpmvv::Model;
using mpmvv::NeoHookean;
using mpmvv::Particles;
using mpmvv::Scheme;
using mpmvv::SolverOptions;
using mpmvv::Stepper;
using mpmvv::Vec2;

// The report's neo-Hookean solid (000_1dbcb8acb6dddab9.txt eq. 2.2).
const NeoHookean kSolid{577.0, 385.0};
constexpr double kDensity = 1000.0;  // rho_0 [kg/m^3]

const Method kMethods[] = {Method::linear, Method::gimp, Method::cpdi, Method::cpdi_exact};
const Scheme kSchemes[] = {Scheme::usl, Scheme::usf, Scheme::musl};

std::string label(Method m, Scheme s) { return std::string(to_string(m)) + "/" + to_string(s); }

// A disk of radius 0.8 m centred on a square domain [-2, 2]^2 of `cells`
// cells per side, seeded on a lattice of two particles per cell per
// direction, at rest and unstressed.
Model disk_model(Method method, int cells = 32) {
  Model model;
  model.grid.origin = Vec2(-2.0, -2.0);
  model.grid.cells_x = model.grid.cells_y = cells;
  model.grid.h = 4.0 / cells;
  const double spacing = 0.5 * model.grid.h;
  const double reference_volume = spacing * spacing;
  std::vector<Vec2> lattice;
  for (int j = 0; j < 2 * cells; ++j)
    for (int i = 0; i < 2 * cells; ++i) {
      const Vec2 x = model.grid.origin + spacing * Vec2(i + 0.5, j + 0.5);
      if (x.norm() < 0.8) lattice.push_back(x);
    }
  Particles& P = model.particles;
  P.resize(lattice.size());
  for (std::size_t p = 0; p < lattice.size(); ++p) {
    P.position[p] = P.reference_position[p] = lattice[p];
    P.mass[p] = kDensity * reference_volume;
    P.volume[p] = P.reference_volume[p] = reference_volume;
  }
  if (method != Method::linear) P.half_size.assign(lattice.size(), Vec2(0.5 * spacing, 0.5 * spacing));
  return model;
}

// One more particle at x, like the disk's, appended to the model.
void add_particle(Model& model, Method method, const Vec2& x) {
  Particles& P = model.particles;
  const double spacing = 0.5 * model.grid.h;
  P.position.push_back(x);
  P.reference_position.push_back(x);
  P.velocity.push_back(Vec2::Zero());
  P.deformation_gradient.push_back(Mat2::Identity());
  P.stress.push_back(Mat2::Zero());
  P.mass.push_back(kDensity * spacing * spacing);
  P.volume.push_back(spacing * spacing);
  P.reference_volume.push_back(spacing * spacing);
  if (method != Method::linear) P.half_size.push_back(Vec2(0.5 * spacing, 0.5 * spacing));
}

double wave_speed() { return std::sqrt(kSolid.p_wave_modulus() / kDensity); }

// dt = 0.3 h / c, well inside the CFL limit of an undeformed grid.
double stable_step(const Model& model) { return 0.3 * model.grid.h / wave_speed(); }

// Central-difference kicks: dt/2 on the first step, dt after.
void advance(Stepper& stepper, int steps, double dt) {
  double t = 0.0;
  for (int k = 0; k < steps; ++k) {
    stepper.step(t, dt, k == 0 ? 0.5 * dt : dt);
    t += dt;
  }
}

Vec2 total_momentum(const Particles& P) {
  Vec2 sum = Vec2::Zero();
  for (std::size_t p = 0; p < P.size(); ++p) sum += P.mass[p] * P.velocity[p];
  return sum;
}

double total_momentum_magnitude(const Particles& P) {
  double sum = 0.0;
  for (std::size_t p = 0; p < P.size(); ++p) sum += P.mass[p] * P.velocity[p].norm();
  return sum;
}

// ---------------------------------------------------------------- momentum

// A velocity field under which the disk shears and stretches everywhere and
// drifts, so that its total momentum is not zero.
void shear_and_stretch(Model& model) {
  for (std::size_t p = 0; p < model.particles.size(); ++p) {
    const Vec2 x = model.particles.position[p];
    model.particles.velocity[p] = Vec2(0.1 * std::sin(x.y()) + 0.02, 0.05 * x.x() - 0.01);
  }
}

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

// ---------------------------------------------------------------- CPDI domains

// After steps that shear and stretch the body, each CPDI domain is still
// s_p = F_p diag(l_p) (eq. 1.97) and its corner polygon has the particle's
// volume V_p = det(F_p) V_p0 (eq. 1.75).
TEST(CpdiDomain, FollowsTheDeformationGradientAfterSteps) {
  Model model = disk_model(Method::cpdi);
  for (std::size_t p = 0; p < model.particles.size(); ++p) {
    const Vec2 x = model.particles.position[p];
    model.particles.velocity[p] = Vec2(0.3 * x.y() + 0.1 * x.x(), -0.05 * x.y());
  }
  const double dt = stable_step(model);
  auto stepper = mpmvv::make_stepper(std::move(model), SolverOptions{Method::cpdi, Scheme::usl},
                                     MaterialModel{kSolid}, nullptr);
  advance(*stepper, 10, dt);
  const Particles& P = stepper->model().particles;
  const mpmvv::CpdiShape shape = mpmvv::CpdiShape::bind(stepper->model().grid, P);
  double largest_shear = 0.0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    const Mat2& F = P.deformation_gradient[p];
    largest_shear = std::max(largest_shear, std::abs(F(0, 1)));
    const Mat2 expected = F * P.half_size[p].asDiagonal();
    const Mat2 s = shape.domain(p);
    EXPECT_LT((s - expected).norm(), 1e-15 * expected.norm());
    double twice_area = 0.0;
    for (int c = 0; c < 4; ++c) {
      const Vec2 a = shape.corner(p, s, c), b = shape.corner(p, s, (c + 1) % 4);
      EXPECT_LT((a - (P.position[p] + mpmvv::CpdiShape::corner_xi[c] * s.col(0) +
                      mpmvv::CpdiShape::corner_eta[c] * s.col(1))).norm(), 1e-15);
      twice_area += a.x() * b.y() - b.x() * a.y();
    }
    // Coordinates of order 1 m give areas of order 4e-3 m^2: 1e-10 relative
    // covers the cancellation of the shoelace sum.
    EXPECT_NEAR(0.5 * twice_area, P.volume[p], 1e-10 * P.volume[p]);
  }
  // The steps really sheared the domains (measured max |F_xy| about 0.1).
  EXPECT_GT(largest_shear, 1e-2);
}

// ---------------------------------------------------------------- failures as data

class NullObserver final : public mpmvv::RunObserver {};

// Records the time after every step.
class StepTimes final : public mpmvv::RunObserver {
 public:
  void after_step(double t, const Stepper&) override { times.push_back(t); }
  std::vector<double> times;
};

mpmvv::TimeLoopOptions short_run(double end_time) {
  mpmvv::TimeLoopOptions o;
  o.end_time = end_time;
  o.cfl = 0.3;
  o.output_times = {end_time};
  return o;
}

// A particle that starts outside the grid, one with det F <= 0 and one with a
// NaN velocity each stop the run before the first step, as data: the reason,
// time 0, step 0 and the particle's index.
TEST(TimeLoop, BadInitialParticleIsReportedAsData) {
  struct Case {
    const char* reason;
    void (*spoil)(Particles&, std::size_t);
  };
  const Case cases[] = {
      {"outside grid", [](Particles& P, std::size_t p) { P.position[p] = Vec2(2.5, 0.0); }},
      {"non-positive J",
       [](Particles& P, std::size_t p) { P.deformation_gradient[p] = Vec2(1.0, -1.0).asDiagonal(); }},
      {"nan", [](Particles& P, std::size_t p) { P.velocity[p].x() = std::numeric_limits<double>::quiet_NaN(); }},
  };
  for (Method method : kMethods)
    for (const Case& c : cases) {
      SCOPED_TRACE(std::string(to_string(method)) + ": " + c.reason);
      Model model = disk_model(method);
      const std::size_t bad = model.particles.size() / 3;
      c.spoil(model.particles, bad);
      auto stepper = mpmvv::make_stepper(std::move(model), SolverOptions{method, Scheme::usl},
                                         MaterialModel{kSolid}, nullptr);
      NullObserver observer;
      const mpmvv::RunOutcome o = mpmvv::run_time_loop(*stepper, short_run(0.1), observer);
      EXPECT_FALSE(o.completed);
      EXPECT_EQ(o.failure_reason, c.reason);
      EXPECT_FALSE(o.failure_detail.empty());
      EXPECT_EQ(o.failure_time, 0.0);
      EXPECT_EQ(o.failure_step, 0);
      EXPECT_EQ(o.failure_particle, static_cast<long long>(bad));
      EXPECT_EQ(o.steps, 0);
      EXPECT_EQ(o.time_reached, 0.0);
      EXPECT_EQ(o.outputs_written, 0u);
    }
}

// ---------------------------------------------------------------- splitting stretched domains

// Splitting (solver/split.hpp) replaces a particle by halves that tile it:
// mass, reference volume, momentum and the first moment of mass (sum m x and
// sum m X) are unchanged, every domain ends no longer than the limit, and
// each half's domain corners lie on its parent's domain.
TEST(CpdiSplit, HalvesTileTheParentAndConserveMassAndMomentum) {
  Particles P;
  P.resize(2);
  P.half_size = {Vec2(0.05, 0.05), Vec2(0.05, 0.05)};
  Mat2 shear;
  shear << 1.0, 4.5, 0.0, 1.0;  // r_2 = (4.5, 1) l: 0.46 m long
  Mat2 stretch;
  stretch << 2.5, 0.3, -0.4, 0.6;
  P.deformation_gradient = {shear, stretch};
  P.position = {Vec2(0.2, -0.1), Vec2(-0.5, 0.7)};
  P.reference_position = {Vec2(0.1, -0.2), Vec2(-0.4, 0.6)};
  P.velocity = {Vec2(1.0, -2.0), Vec2(0.3, 0.25)};
  for (std::size_t p = 0; p < 2; ++p) {
    P.stress[p] = Mat2::Identity() * double(p + 1);
    P.reference_volume[p] = 4.0 * 0.05 * 0.05;
    P.volume[p] = mpmvv::determinant(P.deformation_gradient[p]) * P.reference_volume[p];
    P.mass[p] = 1000.0 * P.reference_volume[p];
  }
  auto totals = [](const Particles& Q) {
    struct {
      double mass = 0.0, volume = 0.0;
      Vec2 momentum = Vec2::Zero(), moment = Vec2::Zero(), reference_moment = Vec2::Zero();
    } t;
    for (std::size_t p = 0; p < Q.size(); ++p) {
      t.mass += Q.mass[p];
      t.volume += Q.volume[p];
      t.momentum += Q.mass[p] * Q.velocity[p];
      t.moment += Q.mass[p] * Q.position[p];
      t.reference_moment += Q.mass[p] * Q.reference_position[p];
    }
    return t;
  };
  const auto before = totals(P);
  const Particles parent = P;
  const double limit = 0.12;
  const std::size_t splits = mpmvv::split_long_domains(P, limit);
  EXPECT_EQ(splits, P.size() - 2);
  EXPECT_GE(splits, 4u);  // the 0.46 m shear domain alone needs two halvings
  const auto after = totals(P);
  EXPECT_NEAR(after.mass, before.mass, 1e-14 * before.mass);
  EXPECT_NEAR(after.volume, before.volume, 1e-14 * before.volume);
  EXPECT_LT((after.momentum - before.momentum).norm(), 1e-14 * before.momentum.norm());
  EXPECT_LT((after.moment - before.moment).norm(), 1e-14);
  EXPECT_LT((after.reference_moment - before.reference_moment).norm(), 1e-14);
  for (std::size_t p = 0; p < P.size(); ++p) {
    const Mat2 s = P.deformation_gradient[p] * P.half_size[p].asDiagonal();
    EXPECT_LE(2.0 * s.col(0).norm(), limit);
    EXPECT_LE(2.0 * s.col(1).norm(), limit);
    // Which parent: the one whose F it carries; the half's centre and its
    // reference centre are on the parent's affine map, x - x_q = F (X - X_q).
    const std::size_t q = P.deformation_gradient[p] == shear ? 0 : 1;
    EXPECT_LT((P.position[p] - parent.position[q] -
               parent.deformation_gradient[q] * (P.reference_position[p] - parent.reference_position[q]))
                  .norm(),
              1e-14);
    EXPECT_EQ(P.velocity[p], parent.velocity[q]);
    EXPECT_EQ(P.stress[p], parent.stress[q]);
  }
}

// A run that splits keeps going over its growing particle set: the sheared
// disk of the domain tests, with domains limited to half a cell, completes,
// ends with more particles, and keeps its mass and momentum.
TEST(CpdiSplit, RunWithSplittingCompletesAndConserves) {
  Model model = disk_model(Method::cpdi);
  for (std::size_t p = 0; p < model.particles.size(); ++p) {
    const Vec2 x = model.particles.position[p];
    model.particles.velocity[p] = Vec2(0.3 * x.y() + 0.1 * x.x(), -0.05 * x.y());
  }
  const std::size_t n0 = model.particles.size();
  const Vec2 momentum = total_momentum(model.particles);
  double mass = 0.0;
  for (double m : model.particles.mass) mass += m;
  SolverOptions options{Method::cpdi, Scheme::usl};
  options.split_domains_beyond = 0.5;  // the seeded domains are exactly half a cell
  auto stepper = mpmvv::make_stepper(std::move(model), options, MaterialModel{kSolid}, nullptr);
  NullObserver observer;
  const mpmvv::RunOutcome o = mpmvv::run_time_loop(*stepper, short_run(0.5), observer);
  EXPECT_TRUE(o.completed) << o.failure_reason << " " << o.failure_detail;
  const Particles& P = stepper->model().particles;
  EXPECT_GT(P.size(), n0);
  double mass_after = 0.0;
  for (double m : P.mass) mass_after += m;
  EXPECT_NEAR(mass_after, mass, 1e-12 * mass);
  EXPECT_LT((total_momentum(P) - momentum).norm(), 1e-10 * total_momentum_magnitude(P));
  EXPECT_GT(o.particle_steps, static_cast<long long>(o.steps * n0));
}

// Splitting is for CPDI in plane strain with one body.
TEST(CpdiSplit, MakeStepperRefusesSplittingElsewhere) {
  SolverOptions gimp{Method::gimp, Scheme::usl};
  gimp.split_domains_beyond = 1.0;
  EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::gimp), gimp, MaterialModel{kSolid}, nullptr),
               std::invalid_argument);
  SolverOptions negative{Method::cpdi, Scheme::usl};
  negative.split_domains_beyond = -1.0;
  EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::cpdi), negative, MaterialModel{kSolid}, nullptr),
               std::invalid_argument);
}

// ---------------------------------------------------------------- domain angle

namespace {

// The cosine of the angle between the columns of s.
double side_cosine(const Mat2& s) { return s.col(0).dot(s.col(1)) / (s.col(0).norm() * s.col(1).norm()); }

// Second moment of area of the domain x_p + s xi, xi in [-1, 1]^2, about o.
Mat2 second_moment(const Mat2& s, const Vec2& centre, const Vec2& o) {
  const double area = 4.0 * std::abs(mpmvv::determinant(s));
  return area / 3.0 * s * s.transpose() + area * (centre - o) * (centre - o).transpose();
}

// Four domains: sheared to 18 degrees (gamma = 3), stretched and skewed to
// 73 degrees, barely sheared (79 degrees) and unsheared.
Particles domains_to_turn() {
  Particles P;
  P.resize(4);
  P.half_size.assign(4, Vec2(0.05, 0.04));
  Mat2 shear, skew, mild;
  shear << 1.0, 3.0, 0.0, 1.0;
  skew << 2.5, 0.3, -0.4, 0.6;
  mild << 1.0, 0.2, 0.0, 1.0;
  P.deformation_gradient = {shear, skew, mild, Mat2::Identity()};
  for (std::size_t p = 0; p < 4; ++p) {
    P.position[p] = Vec2(0.3 * double(p), -0.2);
    P.reference_position[p] = Vec2(0.25 * double(p), -0.1);
    P.reference_volume[p] = 4.0 * 0.05 * 0.04;
    P.volume[p] = mpmvv::determinant(P.deformation_gradient[p]) * P.reference_volume[p];
    P.mass[p] = 1000.0 * P.reference_volume[p];
  }
  return P;
}

}  // namespace

// A domain whose sides meet below the set angle is turned within the
// parallelograms of its centroid, area and second moment of area (in both
// configurations) until they meet at that angle, by the smallest turn; the
// others are left as they are; a second pass finds nothing left to turn.
TEST(CpdiDomainAngle, TurnKeepsTheMomentsAndOpensTheSidesToTheSetAngle) {
  Particles P = domains_to_turn();
  mpmvv::start_domain_axes(P);
  const Particles before = P;
  const double max_cos = std::cos(30.0 * std::numbers::pi / 180.0);
  EXPECT_EQ(mpmvv::open_sheared_domains(P, max_cos), 1u);  // only the 18-degree one is below 30 degrees
  const double wide = std::cos(75.0 * std::numbers::pi / 180.0);
  Particles P75 = before;
  EXPECT_EQ(mpmvv::open_sheared_domains(P75, wide), 2u);  // and the 73-degree one below 75
  for (const auto& [after, limit] : {std::pair<const Particles*, double>{&P, max_cos}, {&P75, wide}}) {
    for (std::size_t p = 0; p < 4; ++p) {
      SCOPED_TRACE("particle " + std::to_string(p) + ", limit " + std::to_string(limit));
      const Mat2 A0 = before.domain_axes[p], A = after->domain_axes[p];
      const Mat2 s0 = before.deformation_gradient[p] * A0, s = after->deformation_gradient[p] * A;
      const Vec2 x = after->position[p];
      EXPECT_LT((second_moment(s, x, x) - second_moment(s0, x, x)).norm(), 1e-14 * second_moment(s0, x, x).norm());
      EXPECT_LT((A * A.transpose() - A0 * A0.transpose()).norm(), 1e-14 * (A0 * A0.transpose()).norm());
      EXPECT_NEAR(mpmvv::determinant(A), mpmvv::determinant(A0), 1e-15);
      if (std::abs(side_cosine(s0)) > limit) {
        EXPECT_NEAR(std::abs(side_cosine(s)), limit, 1e-12);
        // The smallest turn: nine tenths of it leave the sides closer than the limit.
        const Mat2 W = mpmvv::inverse(A0) * A;
        const double t = 0.9 * std::atan2(W(1, 0), W(0, 0));
        Mat2 part;
        part << std::cos(t), -std::sin(t), std::sin(t), std::cos(t);
        EXPECT_GT(std::abs(side_cosine(s0 * part)), limit);
      } else {
        EXPECT_EQ(A, A0);
      }
    }
  }
  const Particles turned = P;
  mpmvv::open_sheared_domains(P, max_cos);
  for (std::size_t p = 0; p < 4; ++p)
    EXPECT_LT((P.domain_axes[p] - turned.domain_axes[p]).norm(), 1e-14) << "particle " << p;
}

// A turned domain splits along its own half-vectors: the halves' centres lie
// on the parent's affine map, x - x_p = F (X - X_p), and together they carry
// the parent's mass and second moment of area about its centroid.
TEST(CpdiDomainAngle, TurnedDomainSplitsIntoHalvesThatTileIt) {
  Particles P = domains_to_turn();
  mpmvv::start_domain_axes(P);
  mpmvv::open_sheared_domains(P, std::cos(60.0 * std::numbers::pi / 180.0));
  const Particles parent = P;
  const double limit = 0.15;
  const std::size_t splits = mpmvv::split_long_domains(P, limit);
  EXPECT_GE(splits, 2u);
  ASSERT_EQ(P.domain_axes.size(), P.size());
  for (std::size_t q = 0; q < parent.size(); ++q) {
    SCOPED_TRACE("parent " + std::to_string(q));
    const Vec2 xq = parent.position[q];
    const Mat2 sq = parent.deformation_gradient[q] * parent.domain_axes[q];
    Mat2 moment = Mat2::Zero();
    double mass = 0.0;
    for (std::size_t p = 0; p < P.size(); ++p) {
      if (P.deformation_gradient[p] != parent.deformation_gradient[q]) continue;
      const Mat2 s = P.deformation_gradient[p] * P.domain_axes[p];
      EXPECT_LE(2.0 * s.col(0).norm(), limit * (1.0 + 1e-14));
      EXPECT_LE(2.0 * s.col(1).norm(), limit * (1.0 + 1e-14));
      EXPECT_LT((P.position[p] - xq - parent.deformation_gradient[q] *
                                         (P.reference_position[p] - parent.reference_position[q]))
                    .norm(),
                1e-14);
      moment += second_moment(s, P.position[p], xq);
      mass += P.mass[p];
    }
    EXPECT_NEAR(mass, parent.mass[q], 1e-14 * parent.mass[q]);
    EXPECT_LT((moment - second_moment(sq, xq, xq)).norm(), 1e-12 * second_moment(sq, xq, xq).norm());
  }
}

// The angle is for CPDI in plane strain under the updated formulation, from
// 0 (never) to below a right angle.
TEST(CpdiDomainAngle, MakeStepperRefusesTheAngleElsewhere) {
  SolverOptions gimp{Method::gimp, Scheme::usl};
  gimp.min_domain_angle = 30.0;
  EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::gimp), gimp, MaterialModel{kSolid}, nullptr),
               std::invalid_argument);
  for (double angle : {-1.0, 90.0}) {
    SolverOptions cpdi{Method::cpdi, Scheme::usl};
    cpdi.min_domain_angle = angle;
    EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::cpdi), cpdi, MaterialModel{kSolid}, nullptr),
                 std::invalid_argument)
        << angle;
  }
  SolverOptions total{Method::cpdi, Scheme::usl};
  total.formulation = mpmvv::Formulation::total;
  total.min_domain_angle = 30.0;
  EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::cpdi), total, MaterialModel{kSolid}, nullptr),
               std::invalid_argument);
  SolverOptions fine{Method::cpdi, Scheme::usl};
  fine.min_domain_angle = 30.0;
  EXPECT_NO_THROW(mpmvv::make_stepper(disk_model(Method::cpdi), fine, MaterialModel{kSolid}, nullptr));
}

// ---------------------------------------------------------------- corner domains

namespace {

using CornerShape = mpmvv::CpdiShapeT<mpmvv::Geometry::plane_strain, mpmvv::CpdiForm::corners>;

// The node weights and gradients of a stencil, summed per node.
struct NodeSums {
  std::map<int, double> weight;
  std::map<int, Vec2> gradient;
};
template <class Shape>
NodeSums node_sums(const Shape& shape, std::size_t p) {
  mpmvv::Stencil<Shape::stencil_size> st;
  shape.evaluate(p, st);
  NodeSums sums;
  for (int k = 0; k < st.count; ++k) {
    sums.weight[st.node[k]] += st.weight[k];
    auto [it, fresh] = sums.gradient.try_emplace(st.node[k], Vec2::Zero());
    it->second += st.gradient[k];
  }
  return sums;
}

Vec2 node_position(const mpmvv::GridGeometry& g, int node) {
  return g.origin + g.h * Vec2(node % g.nodes_x(), node / g.nodes_x());
}

}  // namespace

// A quadrilateral that is a parallelogram weighs the grid exactly as the
// convected domain F_p diag(l_p) it was made from (eq. 1.97): the corner
// form's closed-form factors reduce to the parallelogram's.
TEST(CpdiCorners, ParallelogramWeighsTheGridAsTheConvectedDomain) {
  Model model = disk_model(Method::cpdi, 8);
  Particles& P = model.particles;
  Mat2 F;
  F << 1.3, 2.1, -0.2, 0.9;
  P.deformation_gradient.assign(P.size(), F);
  // Every other domain stretched over more than 2 x 2 cells, the stencil's long form.
  for (std::size_t p = 1; p < P.size(); p += 2) P.half_size[p] = Vec2(0.3, 0.2);
  mpmvv::start_domain_corners(P);
  const mpmvv::CpdiShape convected = mpmvv::CpdiShape::bind(model.grid, P);
  const CornerShape corners = CornerShape::bind(model.grid, P);
  for (std::size_t p = 0; p < P.size(); p += 3) {
    SCOPED_TRACE("particle " + std::to_string(p));
    EXPECT_LT((corners.domain(p) - convected.domain(p)).norm(), 1e-15);
    const NodeSums a = node_sums(convected, p), b = node_sums(corners, p);
    ASSERT_EQ(a.weight.size(), b.weight.size());
    for (const auto& [node, w] : a.weight) {
      EXPECT_NEAR(b.weight.at(node), w, 1e-14);
      EXPECT_LT((b.gradient.at(node) - a.gradient.at(node)).norm(), 1e-12 * (1.0 + a.gradient.at(node).norm()));
    }
  }
}

// On a quadrilateral that is no parallelogram the corner form is the exact
// mean over the domain of the hats interpolated from its corners: it matches
// 2 x 2 Gauss quadrature of that mean on the bilinear map (exact for its
// polynomial degree), is a partition of unity with gradients summing to zero,
// and reproduces linear fields, sum_g S_gp x_g being the domain's centroid of
// area and sum_g x_g (x) G_gp the identity.
TEST(CpdiCorners, QuadrilateralIsTheExactMeanOfTheInterpolatedHats) {
  Model model = disk_model(Method::cpdi, 8);
  Particles& P = model.particles;
  P.resize(1);
  P.half_size.resize(1);
  P.position[0] = Vec2(0.13, -0.21);
  P.domain_corner = {Vec2(-0.31, -0.52), Vec2(0.61, -0.43), Vec2(0.75, 0.27), Vec2(-0.12, 0.08)};
  const mpmvv::GridGeometry& g = model.grid;
  const CornerShape shape = CornerShape::bind(g, P);
  const NodeSums sums = node_sums(shape, 0);
  // The quadrature: x(xi, eta) = sum_c phi_c x_c, dA = det J dxi deta.
  const double gauss = 1.0 / std::sqrt(3.0);
  std::map<int, double> weight;
  std::map<int, Vec2> gradient;
  double area = 0.0;
  Vec2 centroid = Vec2::Zero();
  const Vec2* x = P.domain_corner.data();
  for (double xi : {-gauss, gauss})
    for (double eta : {-gauss, gauss}) {
      Mat2 J = Mat2::Zero();  // columns dx/dxi, dx/deta
      double phi[4];
      Vec2 dphi[4];  // (d/dxi, d/deta)
      for (int c = 0; c < 4; ++c) {
        const double a = mpmvv::kCornerXi[c], b = mpmvv::kCornerEta[c];
        phi[c] = 0.25 * (1 + a * xi) * (1 + b * eta);
        dphi[c] = Vec2(0.25 * a * (1 + b * eta), 0.25 * b * (1 + a * xi));
        J.col(0) += dphi[c].x() * x[c];
        J.col(1) += dphi[c].y() * x[c];
      }
      const double det = mpmvv::determinant(J);
      const Mat2 inverse_transpose = mpmvv::inverse(J).transpose();
      Vec2 point = Vec2::Zero();
      for (int c = 0; c < 4; ++c) point += phi[c] * x[c];
      area += det;
      centroid += det * point;
      for (int c = 0; c < 4; ++c) {
        int node[4];
        double hat[4];
        mpmvv::bilinear_cell_weights(g, x[c], node, hat);
        for (int k = 0; k < 4; ++k) {
          weight[node[k]] += det * phi[c] * hat[k];
          auto [it, fresh] = gradient.try_emplace(node[k], Vec2::Zero());
          it->second += det * hat[k] * (inverse_transpose * dphi[c]);
        }
      }
    }
  centroid /= area;
  double total = 0.0;
  Vec2 gradient_total = Vec2::Zero(), first_moment = Vec2::Zero();
  Mat2 gradient_moment = Mat2::Zero();
  for (const auto& [node, w] : sums.weight) {
    EXPECT_NEAR(w, weight.at(node) / area, 1e-14) << "node " << node;
    EXPECT_LT((sums.gradient.at(node) - gradient.at(node) / area).norm(), 1e-12) << "node " << node;
    total += w;
    gradient_total += sums.gradient.at(node);
    first_moment += w * node_position(g, node);
    gradient_moment += node_position(g, node) * sums.gradient.at(node).transpose();
  }
  EXPECT_EQ(sums.weight.size(), weight.size());
  EXPECT_NEAR(total, 1.0, 1e-14);
  EXPECT_LT(gradient_total.norm(), 1e-12);
  EXPECT_LT((first_moment - centroid).norm(), 1e-14);
  EXPECT_LT((gradient_moment - Mat2::Identity()).norm(), 1e-12);
  // Not a parallelogram: the centroid of area is not the corners' mean.
  EXPECT_GT((centroid - 0.25 * (x[0] + x[1] + x[2] + x[3])).norm(), 1e-3);
}

// The corners move with the grid velocity read with the hats: an affine grid
// motion v = B x + b moves each corner by dt (B x_c + b), exactly (the hats
// reproduce linear fields).
TEST(CpdiCorners, CornersFollowAnAffineGridMotion) {
  Model model = disk_model(Method::cpdi, 8);
  const mpmvv::GridGeometry& g = model.grid;
  mpmvv::GridFields fields;
  fields.resize(g.node_count());
  Mat2 B;
  B << 0.3, -1.2, 0.7, -0.1;
  const Vec2 b(0.05, -0.2);
  for (std::size_t i = 0; i < g.node_count(); ++i) fields.velocity[i] = B * node_position(g, int(i)) + b;
  std::vector<Vec2> corners = {Vec2(-1.23, 0.4), Vec2(0.011, -0.77), Vec2(1.5, 1.49)}, moved;
  const double dt = 0.01;
  mpmvv::move_corners(g, fields, corners, moved, dt);
  for (std::size_t k = 0; k < corners.size(); ++k)
    EXPECT_LT((moved[k] - corners[k] - dt * (B * corners[k] + b)).norm(), 1e-15) << "corner " << k;
}

// Under a shearing, stretching motion the corners that neighbouring
// particles share at the start stay shared, so the domains keep tiling the
// disk, while each particle's parallelogram F_p diag(l_p) leaves its
// neighbours'; the corners moved in earnest. The same under exact CPDI, which
// integrates the hats over the quadrilaterals the stepper moves alike.
TEST(CpdiCorners, NeighboursKeepSharingTheirCornersUnderShear) {
  for (Method method : {Method::cpdi, Method::cpdi_exact})
  for (Scheme scheme : kSchemes) {
    SCOPED_TRACE(to_string(method) + std::string(" ") + to_string(scheme));
    Model model = disk_model(method);
    shear_and_stretch(model);
    const double dt = stable_step(model);
    SolverOptions options{method, scheme};
    options.cpdi_domain = mpmvv::CpdiDomain::corners;
    auto stepper = mpmvv::make_stepper(std::move(model), options, MaterialModel{kSolid}, nullptr);
    const std::vector<Vec2> start = stepper->model().particles.domain_corner;
    advance(*stepper, 40, dt);
    const Particles& P = stepper->model().particles;
    ASSERT_EQ(P.domain_corner.size(), 4 * P.size());
    // Group the corners by where they started (to the lattice's round-off).
    std::map<std::pair<long, long>, std::vector<std::size_t>> shared;
    for (std::size_t k = 0; k < start.size(); ++k)
      shared[{std::lround(start[k].x() * 1e9), std::lround(start[k].y() * 1e9)}].push_back(k);
    double apart = 0.0, moved = 0.0, convected_apart = 0.0;
    std::size_t pairs = 0;
    for (const auto& [key, members] : shared)
      for (std::size_t m = 1; m < members.size(); ++m, ++pairs) {
        const std::size_t a = members[0], b = members[m];
        apart = std::max(apart, (P.domain_corner[a] - P.domain_corner[b]).norm());
        moved = std::max(moved, (P.domain_corner[a] - start[a]).norm());
        // The same two corners as their particles' parallelograms place them.
        auto convected = [&](std::size_t k) {
          const std::size_t p = k / 4;
          const int c = int(k % 4);
          const Mat2 s = P.deformation_gradient[p] * P.half_size[p].asDiagonal();
          return Vec2(P.position[p] + mpmvv::kCornerXi[c] * s.col(0) + mpmvv::kCornerEta[c] * s.col(1));
        };
        convected_apart = std::max(convected_apart, (convected(a) - convected(b)).norm());
      }
    EXPECT_GT(pairs, P.size());  // an interior corner is shared by four particles: three pairs
    EXPECT_LT(apart, 1e-14);
    EXPECT_GT(moved, 1e-3);
    EXPECT_GT(convected_apart, 1e3 * std::max(apart, 1e-16));
    RecordProperty(std::string("convected_gap_") + to_string(method) + "_" + to_string(scheme), scientific(convected_apart));
  }
}

// A split cuts the quadrilateral at the midpoints of the two edges along its
// longer half-vector: the halves share the cut edge, each keeps the corners
// on its side, and their areas sum to the parent's.
TEST(CpdiCorners, SplitHalvesShareTheCutEdgeAndTheParentsArea) {
  Particles P;
  P.resize(1);
  P.half_size = {Vec2(0.05, 0.05)};
  P.reference_volume[0] = 0.01;
  P.volume[0] = P.reference_volume[0];
  P.mass[0] = 10.0;
  P.domain_corner = {Vec2(0.0, 0.0), Vec2(0.1, 0.02), Vec2(0.52, 0.13), Vec2(0.4, 0.1)};
  auto area = [](const Vec2* x) {
    double twice = 0.0;
    for (int c = 0; c < 4; ++c) twice += x[c].x() * x[(c + 1) % 4].y() - x[(c + 1) % 4].x() * x[c].y();
    return 0.5 * twice;
  };
  const double parent_area = area(P.domain_corner.data());
  const std::vector<Vec2> parent = P.domain_corner;
  EXPECT_EQ(mpmvv::split_long_domains(P, 0.3), 1u);  // the eta side, about 0.44 m, is cut once
  ASSERT_EQ(P.domain_corner.size(), 8u);
  const Vec2* minus = &P.domain_corner[0];
  const Vec2* plus = &P.domain_corner[4];
  EXPECT_NEAR(area(minus) + area(plus), parent_area, 1e-15);
  EXPECT_EQ(minus[0], parent[0]);
  EXPECT_EQ(minus[1], parent[1]);
  EXPECT_EQ(plus[2], parent[2]);
  EXPECT_EQ(plus[3], parent[3]);
  EXPECT_EQ(minus[2], plus[1]);
  EXPECT_EQ(minus[3], plus[0]);
  EXPECT_LT((minus[3] - 0.5 * (parent[0] + parent[3])).norm(), 1e-16);
  EXPECT_NEAR(P.half_size[0].y(), 0.025, 1e-17);
  EXPECT_NEAR(P.mass[0] + P.mass[1], 10.0, 1e-14);
}

// Corner domains are for CPDI in plane strain, under the updated formulation,
// with one body, and not with turned domains.
TEST(CpdiCorners, MakeStepperRefusesCornersElsewhere) {
  auto options = [](Method method) {
    SolverOptions o{method, Scheme::usl};
    o.cpdi_domain = mpmvv::CpdiDomain::corners;
    return o;
  };
  EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::gimp), options(Method::gimp), MaterialModel{kSolid}, nullptr),
               std::invalid_argument);
  SolverOptions total = options(Method::cpdi);
  total.formulation = mpmvv::Formulation::total;
  EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::cpdi), total, MaterialModel{kSolid}, nullptr),
               std::invalid_argument);
  SolverOptions turned = options(Method::cpdi);
  turned.min_domain_angle = 30.0;
  EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::cpdi), turned, MaterialModel{kSolid}, nullptr),
               std::invalid_argument);
  SolverOptions split = options(Method::cpdi);
  split.split_domains_beyond = 0.5;
  EXPECT_NO_THROW(mpmvv::make_stepper(disk_model(Method::cpdi), split, MaterialModel{kSolid}, nullptr));
  // Exact CPDI splits corner domains, not its parallelograms (their outlines
  // would not follow), and corner domains replace particle outlines.
  SolverOptions exact_split = options(Method::cpdi_exact);
  exact_split.split_domains_beyond = 0.5;
  EXPECT_NO_THROW(mpmvv::make_stepper(disk_model(Method::cpdi_exact), exact_split, MaterialModel{kSolid}, nullptr));
  exact_split.cpdi_domain = mpmvv::CpdiDomain::convected;
  EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::cpdi_exact), exact_split, MaterialModel{kSolid}, nullptr),
               std::invalid_argument);
  Model outlined = disk_model(Method::cpdi_exact);
  const double l = outlined.particles.half_size[0].x();
  outlined.particles.domain_first.assign(outlined.particles.size() + 1, 0);
  for (std::size_t p = 0; p < outlined.particles.size(); ++p) {
    for (const Vec2& v : {Vec2(-l, -l), Vec2(l, -l), Vec2(l, l), Vec2(-l, l)}) outlined.particles.domain_vertex.push_back(v);
    outlined.particles.domain_first[p + 1] = std::uint32_t(outlined.particles.domain_vertex.size());
  }
  EXPECT_THROW(mpmvv::make_stepper(std::move(outlined), options(Method::cpdi_exact), MaterialModel{kSolid}, nullptr),
               std::invalid_argument);
}

// Exact CPDI's stencil holds 3 x 3 cells: a particle stretched beyond them
// stops the run with its own reason, not as "outside grid".
TEST(TimeLoop, ExactCpdiDomainBeyondItsStencilIsReportedAsTooWide) {
  Model model = disk_model(Method::cpdi_exact);
  const std::size_t bad = model.particles.size() / 3;
  model.particles.deformation_gradient[bad] = Vec2(14.0, 1.0 / 14.0).asDiagonal();  // 7 cells long
  auto stepper = mpmvv::make_stepper(std::move(model), SolverOptions{Method::cpdi_exact, Scheme::usl},
                                     MaterialModel{kSolid}, nullptr);
  NullObserver observer;
  const mpmvv::RunOutcome o = mpmvv::run_time_loop(*stepper, short_run(0.1), observer);
  EXPECT_FALSE(o.completed);
  EXPECT_EQ(o.failure_reason, "domain too wide");
  EXPECT_EQ(o.failure_particle, static_cast<long long>(bad));
}

// A body force that turns NaN for one lone particle from t = 0.2 s on.
class PoisonAfter final : public mpmvv::BodyForce {
 public:
  PoisonAfter(std::size_t particle, double time) : particle_(particle), time_(time) {}
  void evaluate(double t, const Particles& P, std::vector<Vec2>& b) const override {
    std::fill(b.begin(), b.begin() + std::ptrdiff_t(P.size()), Vec2::Zero());
    if (t >= time_) b[particle_] = Vec2(std::numeric_limits<double>::quiet_NaN(), 0.0);
  }

 private:
  std::size_t particle_;
  double time_;
};

// A particle that goes bad during the run stops it at the end of that step:
// failure_time is the time that step reached and failure_step its number.
TEST(TimeLoop, FailureDuringTheRunRecordsTimeAndStep) {
  for (Method method : kMethods) {
    SCOPED_TRACE(to_string(method));
    Model model = disk_model(method);
    add_particle(model, method, Vec2(1.5, 1.5));  // far from the disk: only it is poisoned
    const std::size_t lone = model.particles.size() - 1;
    auto stepper = mpmvv::make_stepper(std::move(model), SolverOptions{method, Scheme::usl},
                                       MaterialModel{kSolid}, std::make_shared<PoisonAfter>(lone, 0.2));
    StepTimes observer;
    const mpmvv::RunOutcome o = mpmvv::run_time_loop(*stepper, short_run(1.0), observer);
    EXPECT_FALSE(o.completed);
    EXPECT_EQ(o.failure_reason, "nan");
    EXPECT_EQ(o.failure_particle, static_cast<long long>(lone));
    const std::size_t n = observer.times.size();
    ASSERT_GE(n, 3u);
    // The first step that starts at t >= 0.2 s is the last one taken.
    EXPECT_EQ(o.failure_step, static_cast<long long>(n));
    EXPECT_EQ(o.steps, o.failure_step);
    EXPECT_EQ(o.failure_time, observer.times.back());
    EXPECT_EQ(o.time_reached, o.failure_time);
    EXPECT_GE(observer.times[n - 2], 0.2);
    EXPECT_LT(observer.times[n - 3], 0.2);
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

// ---------------------------------------------------------------- time loop

// Passes every call to a real stepper and records what the time loop asked
// for, with the CFL bound at that moment.
class RecordingStepper final : public Stepper {
 public:
  struct Call {
    double t, dt, kick, cfl_bound;
  };

  RecordingStepper(std::unique_ptr<Stepper> inner, double cfl)
      : Stepper(inner->model()), inner_(std::move(inner)), cfl_(cfl) {}

  void step(double t, double dt, double kick) override {
    const double bound = cfl_ * inner_->model().grid.h / inner_->scan().max_signal_speed;
    calls.push_back({t, dt, kick, bound});
    inner_->step(t, dt, kick);
  }
  mpmvv::ParticleScan scan() const override { return inner_->scan(); }
  mpmvv::ParticleFault diagnose(std::size_t p) const override { return inner_->diagnose(p); }
  mpmvv::Monitors monitors() const override { return inner_->monitors(); }

  std::vector<Call> calls;

 private:
  std::unique_ptr<Stepper> inner_;
  double cfl_;
};

class OutputTimes final : public mpmvv::RunObserver {
 public:
  void at_output(std::size_t index, double t, const Stepper&) override { outputs.emplace_back(index, t); }
  std::vector<std::pair<std::size_t, double>> outputs;
};

// The loop lands exactly on every output time, never takes a step longer
// than cfl h / max(c + |v|), passes each step the time the last one reached,
// and kicks by dt/2 first and by the mean of adjacent steps after
// (central differences).
TEST(TimeLoop, LandsOnOutputTimesWithinTheCflStep) {
  Model model = disk_model(Method::gimp);
  for (std::size_t p = 0; p < model.particles.size(); ++p) {
    const Vec2 x = model.particles.position[p];
    model.particles.velocity[p] = Vec2(0.4 * x.y(), -0.3 * x.x());
  }
  mpmvv::TimeLoopOptions options;
  options.cfl = 0.4;
  options.end_time = 0.5;
  options.output_times = {0.03, 0.1, 1.0 / 3.0, 0.35, 0.5};
  auto inner = mpmvv::make_stepper(std::move(model), SolverOptions{Method::gimp, Scheme::usl},
                                   MaterialModel{kSolid}, nullptr);
  RecordingStepper stepper(std::move(inner), options.cfl);
  OutputTimes observer;
  const mpmvv::RunOutcome o = mpmvv::run_time_loop(stepper, options, observer);

  ASSERT_TRUE(o.completed) << o.failure_reason;
  EXPECT_EQ(o.time_reached, options.end_time);
  EXPECT_EQ(o.outputs_written, options.output_times.size());
  ASSERT_EQ(observer.outputs.size(), options.output_times.size());
  for (std::size_t k = 0; k < observer.outputs.size(); ++k) {
    EXPECT_EQ(observer.outputs[k].first, k);
    EXPECT_EQ(observer.outputs[k].second, options.output_times[k]);
  }
  ASSERT_EQ(stepper.calls.size(), std::size_t(o.steps));
  double reached = 0.0;
  for (std::size_t k = 0; k < stepper.calls.size(); ++k) {
    const RecordingStepper::Call& c = stepper.calls[k];
    SCOPED_TRACE("step " + std::to_string(k));
    EXPECT_LE(c.dt, c.cfl_bound);
    EXPECT_GT(c.dt, 0.0);
    EXPECT_EQ(c.t, reached);
    const double expected_kick = k == 0 ? 0.5 * c.dt : 0.5 * (stepper.calls[k - 1].dt + c.dt);
    EXPECT_EQ(c.kick, expected_kick);
    const auto landing = std::find_if(options.output_times.begin(), options.output_times.end(),
                                      [&](double target) { return std::abs(c.t + c.dt - target) < 1e-12; });
    reached = landing != options.output_times.end() ? *landing : c.t + c.dt;
  }
  // Landing never leaves a sliver: the output times here are at least half a
  // CFL step apart, and the loop splits a last stretch shorter than two steps
  // in two, so no step is shorter than a quarter of the CFL step.
  for (const RecordingStepper::Call& c : stepper.calls) EXPECT_GT(c.dt, 0.25 * c.cfl_bound);
}

// The scan a step's map makes (Stepper::prepare_step, stages.hpp: ScanInMap)
// is the scan of the state, bit for bit, and the step it prepares moves every
// particle as a step that maps for itself. The disk is sheared (F = [[1, 4],
// [0, 1]]) so that CPDI's domains span four cells and its full stencils, whose
// repeated nodes the stiffening merges, set the speed; under USL and MUSL, the
// schemes that map first. A particle that stops the run is the same lowest one.
TEST(TimeLoop, AStepPreparedByItsMapScansAndMovesAsOneThatMapsItself) {
  for (Scheme scheme : {Scheme::usl, Scheme::musl}) {
    SCOPED_TRACE(to_string(scheme));
    Model model = disk_model(Method::cpdi);
    Mat2 F;
    F << 1.0, 4.0, 0.0, 1.0;
    double bare = 0.0;  // max_p c_p + |v_p|, without CPDI's stiffening
    for (std::size_t p = 0; p < model.particles.size(); ++p) {
      const Vec2 x = model.particles.position[p];
      model.particles.velocity[p] = Vec2(0.4 * x.y(), -0.3 * x.x());
      model.particles.deformation_gradient[p] = F;
      model.particles.stress[p] = kSolid.cauchy_stress(F);
      bare = std::max(bare, std::sqrt(kSolid.wave_modulus(F, model.particles.stress[p]) / kDensity) +
                                model.particles.velocity[p].norm());
    }
    const SolverOptions options{Method::cpdi, scheme};
    auto prepared = mpmvv::make_stepper(model, options, MaterialModel{kSolid}, nullptr);
    auto plain = mpmvv::make_stepper(model, options, MaterialModel{kSolid}, nullptr);
    double t = 0.0;
    for (int k = 0; k < 4; ++k) {
      SCOPED_TRACE("step " + std::to_string(k));
      const mpmvv::ParticleScan full = plain->scan();
      const mpmvv::ParticleScan mapped = prepared->prepare_step(t);
      EXPECT_EQ(mapped.max_signal_speed, full.max_signal_speed);
      ASSERT_EQ(mapped.first_unhealthy, model.particles.size());
      ASSERT_EQ(full.first_unhealthy, model.particles.size());
      // The stiffening sets the speed (3.16 against max c + |v| = 3.12 m/s):
      // the stencils took part.
      if (k == 0) {
        EXPECT_GT(full.max_signal_speed, bare);
      }
      const double dt = 0.4 * model.grid.h / full.max_signal_speed;
      prepared->step(t, dt, dt);
      plain->step(t, dt, dt);
      t += dt;
    }
    const Particles& a = prepared->model().particles;
    const Particles& b = plain->model().particles;
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t p = 0; p < a.size(); ++p) {
      ASSERT_TRUE(a.position[p] == b.position[p]) << "particle " << p;
      ASSERT_TRUE(a.velocity[p] == b.velocity[p]) << "particle " << p;
      ASSERT_TRUE(a.deformation_gradient[p] == b.deformation_gradient[p]) << "particle " << p;
      ASSERT_TRUE(a.stress[p] == b.stress[p]) << "particle " << p;
    }

    Model broken = model;
    broken.particles.velocity[9].x() = std::numeric_limits<double>::quiet_NaN();
    broken.particles.deformation_gradient[4] << -0.5, 0.0, 0.0, 0.5;  // J = -0.25
    auto stopped = mpmvv::make_stepper(broken, options, MaterialModel{kSolid}, nullptr);
    EXPECT_EQ(stopped->scan().first_unhealthy, 4u);
    EXPECT_EQ(stopped->prepare_step(0.0).first_unhealthy, 4u);
    broken.particles.deformation_gradient[4] = F;
    broken.particles.stress[12](1, 0) = std::numeric_limits<double>::infinity();
    auto nan = mpmvv::make_stepper(broken, options, MaterialModel{kSolid}, nullptr);
    EXPECT_EQ(nan->scan().first_unhealthy, 9u);
    EXPECT_EQ(nan->prepare_step(0.0).first_unhealthy, 9u);
    broken.particles.velocity[9].x() = 0.0;
    auto infinite = mpmvv::make_stepper(broken, options, MaterialModel{kSolid}, nullptr);
    EXPECT_EQ(infinite->scan().first_unhealthy, 12u);
    EXPECT_EQ(infinite->prepare_step(0.0).first_unhealthy, 12u);
  }
}

// The memory a run holds per particle (Stepper::bytes_per_particle, the
// throughput benchmark's bytes column): linear MPM's eight arrays, x, v, F,
// V, sigma, m, V0 and X (16 + 16 + 32 + 8 + 32 + 8 + 8 + 16 = 136 bytes); GIMP
// adds its half sizes (16); MUSL's stepper its next positions (16).
TEST(Stepper, BytesPerParticleCountEveryArrayItHolds) {
  auto linear = mpmvv::make_stepper(disk_model(Method::linear), SolverOptions{Method::linear, Scheme::usl},
                                    MaterialModel{kSolid}, nullptr);
  EXPECT_EQ(linear->bytes_per_particle(), 136.0);
  auto gimp = mpmvv::make_stepper(disk_model(Method::gimp), SolverOptions{Method::gimp, Scheme::usl},
                                  MaterialModel{kSolid}, nullptr);
  EXPECT_EQ(gimp->bytes_per_particle(), 152.0);
  auto musl = mpmvv::make_stepper(disk_model(Method::gimp), SolverOptions{Method::gimp, Scheme::musl},
                                  MaterialModel{kSolid}, nullptr);
  EXPECT_EQ(musl->bytes_per_particle(), 168.0);
}

// A body force's own arrays count too (BodyForce::bytes): here 40 bytes a
// particle beside linear MPM's 136 and the body-force array b_p (16).
class KeepingBodyForce final : public mpmvv::BodyForce {
 public:
  void prepare(const Particles& P) override { kept_.assign(5 * P.size(), 0.0); }
  void evaluate(double, const Particles&, std::vector<Vec2>& b) const override {
    for (Vec2& v : b) v.setZero();
  }
  std::size_t bytes() const override { return mpmvv::bytes_held(kept_); }

 private:
  std::vector<double> kept_;
};

TEST(Stepper, BytesPerParticleCountWhatTheBodyForceKeeps) {
  auto stepper = mpmvv::make_stepper(disk_model(Method::linear), SolverOptions{Method::linear, Scheme::usl},
                                     MaterialModel{kSolid}, std::make_shared<KeepingBodyForce>());
  EXPECT_EQ(stepper->bytes_per_particle(), 136.0 + 16.0 + 40.0);
}

// A stepper whose stage gives up at its third step, as a system of rest
// points that does not factor does.
class GivingUpStepper final : public Stepper {
 public:
  explicit GivingUpStepper(std::unique_ptr<Stepper> inner) : Stepper(inner->model()), inner_(std::move(inner)) {}
  void step(double t, double dt, double kick) override {
    if (++steps_ == 3) throw std::runtime_error("rest points: the constraint system could not be factored");
    inner_->step(t, dt, kick);
  }
  mpmvv::ParticleScan scan() const override { return inner_->scan(); }
  mpmvv::ParticleFault diagnose(std::size_t p) const override { return inner_->diagnose(p); }
  mpmvv::Monitors monitors() const override { return inner_->monitors(); }

 private:
  std::unique_ptr<Stepper> inner_;
  int steps_ = 0;
};

// A stage that cannot go on ends the run as failed with the stage's message,
// at the time the last whole step reached, and the loop returns what it has
// (an exception escaping the run would lose the results file).
TEST(TimeLoop, AStageThatGivesUpEndsTheRunAsFailed) {
  auto inner = mpmvv::make_stepper(disk_model(Method::linear), SolverOptions{Method::linear, Scheme::usl},
                                   MaterialModel{kSolid}, nullptr);
  GivingUpStepper stepper(std::move(inner));
  NullObserver observer;
  const mpmvv::RunOutcome o = mpmvv::run_time_loop(stepper, short_run(0.5), observer);
  EXPECT_FALSE(o.completed);
  EXPECT_EQ(o.failure_reason, "stage failed");
  EXPECT_NE(o.failure_detail.find("could not be factored"), std::string::npos) << o.failure_detail;
  EXPECT_EQ(o.steps, 2);
  EXPECT_EQ(o.failure_step, 2);
  EXPECT_GT(o.time_reached, 0.0);
  EXPECT_EQ(o.failure_time, o.time_reached);
}

// Stops the run as a signal would (stop_request), after a given step.
class StopAfter final : public mpmvv::RunObserver {
 public:
  explicit StopAfter(int steps) : steps_(steps) {}
  void after_step(double, const Stepper&) override {
    if (++seen_ == steps_) mpmvv::stop_request().store(true);
  }

 private:
  int steps_, seen_ = 0;
};

// A run stopped between two steps saves its state once (Checkpoints), and a
// stepper built afresh that reads it goes on to the bits of a run that never
// stopped: every particle array, the step count and the time steps. CPDI with
// its domains split when they grow long (the particle count grows), under the
// stable time-step rule (the loop's own measurements are state too).
TEST(TimeLoop, ARunStoppedBySignalSavesItsStateAndGoesOnFromIt) {
  SolverOptions options{Method::cpdi, Scheme::usl};
  options.split_domains_beyond = 0.6;
  auto make = [&] {
    Model model = disk_model(Method::cpdi, 16);
    for (std::size_t p = 0; p < model.particles.size(); ++p) {
      const Vec2 x = model.particles.position[p];
      model.particles.velocity[p] = Vec2(-3.0 * x.y(), 3.0 * x.x());
    }
    return mpmvv::make_stepper(std::move(model), options, MaterialModel{kSolid}, nullptr);
  };
  mpmvv::TimeLoopOptions loop = short_run(0.3);
  loop.output_times = {0.1, 0.2, 0.3};
  loop.step_rule = mpmvv::TimeStepRule::stable;
  loop.track_every = 4;

  auto whole = make();
  NullObserver none;
  const mpmvv::RunOutcome reference = mpmvv::run_time_loop(*whole, loop, none);
  ASSERT_TRUE(reference.completed) << reference.failure_reason;
  ASSERT_GT(whole->model().particles.size(), make()->model().particles.size()) << "no domain was split";
  ASSERT_GE(reference.steps, 6);
  const int stop_after = int(reference.steps / 2);

  const std::string path = (std::filesystem::temp_directory_path() / "mpmvv-loop-state.h5").string();
  int saves = 0;
  mpmvv::LoopState saved;
  mpmvv::Checkpoints checkpoints;
  auto first = make();
  checkpoints.save = [&](const mpmvv::LoopState& state) {
    ++saves;
    saved = state;
    mpmvv::h5::File file = mpmvv::h5::File::create(path);
    {
      mpmvv::StateArchive a = mpmvv::StateArchive::writing(file.root());
      first->persist(a);
    }
    file.save();
  };
  StopAfter stop(stop_after);
  const mpmvv::RunOutcome stopped = mpmvv::run_time_loop(*first, loop, stop, {}, 1.0, checkpoints);
  mpmvv::stop_request().store(false);
  EXPECT_EQ(stopped.failure_reason, mpmvv::kInterrupted);
  EXPECT_EQ(saves, 1);
  EXPECT_EQ(saved.steps, stop_after);
  EXPECT_EQ(saved.t, stopped.time_reached);

  auto second = make();
  {
    const mpmvv::h5::File file = mpmvv::h5::File::open_read(path);
    mpmvv::StateArchive a = mpmvv::StateArchive::reading(file.root());
    second->persist(a);
  }
  mpmvv::Checkpoints going_on;
  going_on.resume = &saved;
  const mpmvv::RunOutcome resumed = mpmvv::run_time_loop(*second, loop, none, {}, 1.0, going_on);
  ASSERT_TRUE(resumed.completed) << resumed.failure_reason;
  EXPECT_EQ(resumed.steps, reference.steps);
  EXPECT_EQ(resumed.particle_steps, reference.particle_steps);
  EXPECT_EQ(resumed.dt_min, reference.dt_min);
  EXPECT_EQ(resumed.dt_max, reference.dt_max);
  EXPECT_EQ(resumed.frequency_measurements, reference.frequency_measurements);
  EXPECT_EQ(resumed.resumed_at, std::vector<double>{saved.t});
  const Particles& a = whole->model().particles;
  const Particles& b = second->model().particles;
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t p = 0; p < a.size(); ++p) {
    EXPECT_EQ(a.position[p], b.position[p]) << p;
    EXPECT_EQ(a.velocity[p], b.velocity[p]) << p;
    EXPECT_EQ(a.deformation_gradient[p], b.deformation_gradient[p]) << p;
    EXPECT_EQ(a.stress[p], b.stress[p]) << p;
    EXPECT_EQ(a.half_size[p], b.half_size[p]) << p;
  }
  std::filesystem::remove(path);
}

// Output times that do not end at the end time are refused before any step.
TEST(TimeLoop, OutputTimesMustEndAtTheEndTime) {
  auto stepper = mpmvv::make_stepper(disk_model(Method::linear), SolverOptions{Method::linear, Scheme::usl},
                                     MaterialModel{kSolid}, nullptr);
  mpmvv::TimeLoopOptions options = short_run(0.5);
  options.output_times = {0.25};
  NullObserver observer;
  EXPECT_THROW(mpmvv::run_time_loop(*stepper, options, observer), std::invalid_argument);
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
