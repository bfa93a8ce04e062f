// The velocity transfer (solver/model.hpp: VelocityTransfer). Under APIC a
// particle carries the affine velocity field v_p + C_p (x - x_p): an affine
// motion goes to the grid and comes back without loss, for every basis of
// the updated formulation; the map keeps the total momentum whatever the
// particles' fields; a split half takes its parent's field at its own centre;
// the combinations it is not built for are refused.
#include <gtest/gtest.h>

#include "support.hpp"

#include <cstddef>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "solver/explicit_stepper.hpp"
#include "solver/parallel.hpp"
#include "solver/shape/bspline.hpp"
#include "solver/shape/cpdi.hpp"
#include "solver/shape/gimp.hpp"
#include "solver/shape/linear.hpp"
#include "solver/split.hpp"
#include "solver/stages.hpp"

namespace {

using mpmvv::GridFields;
using mpmvv::GridGeometry;
using mpmvv::Mat2;
using mpmvv::Model;
using mpmvv::Particles;
using mpmvv::Vec2;

constexpr double kDensity = 1000.0;

// A block of 4 x 4 cells of size 1 in the middle of a 12-cell grid, 2 particles
// per cell and axis, each moved off its lattice point by up to a tenth of the
// spacing (so that a node's particles do not sit symmetrically about it) and
// sheared by F (so that CPDI domains are parallelograms).
Model jittered_block(const Mat2& F) {
  Model model;
  model.grid = GridGeometry::walled(Vec2::Zero(), 1.0, 12, 12);
  const double spacing = 0.5;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.1 * spacing, 0.1 * spacing);
  Particles& P = model.particles;
  const int n = 8;
  P.resize(std::size_t(n * n));
  P.half_size.assign(P.size(), Vec2(0.5 * spacing, 0.5 * spacing));
  std::size_t p = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i, ++p) {
      const Vec2 X = spacing * Vec2(i + 0.5 - 0.5 * n, j + 0.5 - 0.5 * n) + Vec2(jitter(rng), jitter(rng));
      P.reference_position[p] = Vec2(6.0, 6.0) + X;
      P.position[p] = Vec2(6.0, 6.0) + F * X;
      P.deformation_gradient[p] = F;
      P.mass[p] = kDensity * spacing * spacing;
      P.reference_volume[p] = spacing * spacing;
      P.volume[p] = mpmvv::determinant(F) * spacing * spacing;
    }
  return model;
}

template <class Shape>
class VelocityTransferTest : public ::testing::Test {};
using Shapes = ::testing::Types<mpmvv::LinearShape, mpmvv::GimpShape, mpmvv::CpdiShape, mpmvv::BsplineShape,
                                mpmvv::CubicBsplineShape>;
TYPED_TEST_SUITE(VelocityTransferTest, Shapes);

constexpr unsigned kAffineMap = mpmvv::kMass | mpmvv::kMomentum | mpmvv::kAffineMomentum;

}  // namespace

// v = a + B x on the particles, each with C_p = B: every node that takes mass
// gets v(x_g) exactly (the affine field of each particle is v itself), and
// reading the nodes back gives every particle v(x_p) and C_p = B again,
// because each basis reproduces linear fields (sum S x_g = x_p, sum G = 0,
// sum x_g (x) G = I). The plain map of v_p alone does not: the jittered
// particles put each node's mean velocity off v(x_g).
TYPED_TEST(VelocityTransferTest, AffineMotionGoesToTheGridAndBackWithoutLoss) {
  using Shape = TypeParam;
  Model model = jittered_block(mpmvv::testing::simple_shear(0.4));
  Particles& P = model.particles;
  const Vec2 a(0.3, -0.2);
  Mat2 B;
  B << 0.5, -1.3, 0.7, 0.2;
  P.affine_velocity.assign(P.size(), B);
  for (std::size_t p = 0; p < P.size(); ++p) P.velocity[p] = a + B * P.position[p];
  const Shape shape = Shape::bind(model.grid, P);
  mpmvv::ScatterBuffers buffers;
  buffers.resize(mpmvv::max_threads(), model.grid.node_count());
  GridFields g, plain;
  g.resize(model.grid.node_count());
  plain.resize(model.grid.node_count());
  mpmvv::particles_to_grid<kAffineMap>(shape, P, buffers, g, {}, &model.grid);
  mpmvv::particles_to_grid<mpmvv::kMass | mpmvv::kMomentum>(shape, P, buffers, plain);
  double largest_plain_error = 0.0;
  int nodes = 0;
  for (std::size_t i = 0; i < model.grid.node_count(); ++i) {
    if (!(g.mass[i] > 0.0)) continue;
    ++nodes;
    const Vec2 exact = a + B * model.grid.node_position(i);
    g.velocity[i] = g.momentum[i] / g.mass[i];
    EXPECT_LT((g.velocity[i] - exact).norm(), 1e-12) << "node " << i;
    largest_plain_error = std::max(largest_plain_error, (plain.momentum[i] / plain.mass[i] - exact).norm());
  }
  EXPECT_GT(nodes, 30);
  EXPECT_GT(largest_plain_error, 1e-3);
  for (std::size_t p = 0; p < P.size(); ++p) {
    P.velocity[p].setZero();
    P.affine_velocity[p].setZero();
  }
  mpmvv::grid_to_particles<mpmvv::kVelocity | mpmvv::kAffine, Shape>(shape, g, P, 0.0, 0.0);
  for (std::size_t p = 0; p < P.size(); ++p) {
    EXPECT_LT((P.velocity[p] - (a + B * P.position[p])).norm(), 1e-12) << "particle " << p;
    EXPECT_LT((P.affine_velocity[p] - B).norm(), 1e-12) << "particle " << p;
  }
}

// Whatever the particles' velocities and affine fields, the affine map puts
// on the grid the momentum the particles carry: sum_g m_g v_g = sum_p m_p v_p.
TYPED_TEST(VelocityTransferTest, AffineMapKeepsTheTotalMomentum) {
  using Shape = TypeParam;
  Model model = jittered_block(mpmvv::testing::simple_shear(-0.3));
  Particles& P = model.particles;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  P.affine_velocity.resize(P.size());
  Vec2 particle_momentum = Vec2::Zero();
  for (std::size_t p = 0; p < P.size(); ++p) {
    P.velocity[p] = Vec2(u(rng), u(rng));
    P.affine_velocity[p] << u(rng), u(rng), u(rng), u(rng);
    particle_momentum += P.mass[p] * P.velocity[p];
  }
  mpmvv::ScatterBuffers buffers;
  buffers.resize(mpmvv::max_threads(), model.grid.node_count());
  GridFields g;
  g.resize(model.grid.node_count());
  mpmvv::particles_to_grid<kAffineMap>(Shape::bind(model.grid, P), P, buffers, g, {}, &model.grid);
  Vec2 grid_momentum = Vec2::Zero();
  for (const Vec2& m : g.momentum) grid_momentum += m;
  EXPECT_LT((grid_momentum - particle_momentum).norm(), 1e-12 * P.size() * kDensity);
}

// A split half takes its parent's affine field at its own centre, v_p -+ C_p r / 2,
// and keeps C_p: the halves carry the parent's momentum, and the field the
// parent described is the field the halves describe.
TEST(VelocityTransfer, SplitHalvesTakeTheAffineFieldAtTheirCentres) {
  Model model = jittered_block(mpmvv::testing::simple_shear(3.0));
  Particles& P = model.particles;
  P.resize(1);
  P.half_size.resize(1);
  Mat2 C;
  C << 0.2, 1.5, -0.4, 0.1;
  P.affine_velocity.assign(1, C);
  P.velocity[0] = Vec2(1.0, 2.0);
  const Vec2 centre = P.position[0], v = P.velocity[0];
  const double m = P.mass[0];
  ASSERT_EQ(mpmvv::split_long_domains(P, 1.0), 1u);  // 2 |r2| = 2 |F (0, 0.25)| = 1.58, then 0.79
  ASSERT_EQ(P.size(), 2u);
  ASSERT_EQ(P.affine_velocity.size(), 2u);
  Vec2 momentum = Vec2::Zero();
  for (std::size_t p = 0; p < P.size(); ++p) {
    EXPECT_LT((P.velocity[p] - (v + C * (P.position[p] - centre))).norm(), 1e-14) << "half " << p;
    EXPECT_EQ(P.affine_velocity[p], C);
    momentum += P.mass[p] * P.velocity[p];
  }
  EXPECT_LT((momentum - m * v).norm(), 1e-12 * m);
}

// APIC reads x_g - x_p in the current configuration: the total formulation
// (reference positions), r-z and the static step are refused by name.
TEST(VelocityTransfer, RefusesWhatItIsNotBuiltFor) {
  mpmvv::SolverOptions options;
  options.method = mpmvv::Method::gimp;
  options.velocity_transfer = mpmvv::VelocityTransfer::apic;
  const mpmvv::MaterialModel solid = mpmvv::NeoHookean{577.0, 385.0};
  EXPECT_NO_THROW(mpmvv::make_stepper(jittered_block(Mat2::Identity()), options, solid, nullptr));
  options.formulation = mpmvv::Formulation::total;
  try {
    mpmvv::make_stepper(jittered_block(Mat2::Identity()), options, solid, nullptr);
    ADD_FAILURE() << "the total formulation with apic was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("velocity_transfer = apic serves the updated formulation"), std::string::npos)
        << e.what();
  }
}
