// Exact CPDI integration (solver/shape/cpdi_exact.hpp) by what it claims: the
// polygon moments of Green's theorem, S_gp and G_gp equal to the averages of
// the grid basis over the domain (against a fine independent quadrature)
// where the domain crosses cell lines, agreement with the corner formula of
// CPDI where it is exact (inside one cell), and particle outlines: an
// outline equal to the parallelogram changes nothing, and two pieces on a
// bridge integrate as the two pieces would; corner domains: a quadrilateral
// integrates as the same quadrilateral given as an outline, a crossed one as
// the parallelogram of its linear part, and one turned over is not inside.
#include <gtest/gtest.h>

#include "support.hpp"

#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "solver/domain_corners.hpp"
#include "solver/material/neo_hookean.hpp"
#include "solver/monitors.hpp"
#include "solver/particles.hpp"
#include "solver/parallel.hpp"
#include "solver/shape/stored_stencils.hpp"
#include "solver/stages.hpp"
#include "solver/shape/cpdi.hpp"
#include "solver/shape/cpdi_exact.hpp"

namespace {

using mpmvv::CpdiExactShape;
using mpmvv::CpdiShape;
using mpmvv::GridGeometry;
using mpmvv::Mat2;
using mpmvv::Particles;
using mpmvv::Stencil;
using mpmvv::Vec2;

GridGeometry grid_of(double h) {
  GridGeometry g;
  g.origin = Vec2(-1.0, -0.5);
  g.h = h;
  g.cells_x = 12;
  g.cells_y = 12;
  return g;
}

Particles one_particle(const Vec2& x, const Mat2& F, const Vec2& half_size) {
  Particles P;
  P.resize(1);
  P.position[0] = x;
  P.deformation_gradient[0] = F;
  P.half_size.assign(1, half_size);
  P.reference_volume[0] = 4.0 * half_size.x() * half_size.y();
  P.volume[0] = mpmvv::determinant(F) * P.reference_volume[0];
  return P;
}

// Node -> (weight, gradient), duplicates summed, zero entries dropped.
struct NodeValues {
  double weight = 0.0;
  Vec2 gradient = Vec2::Zero();
};
template <int N>
std::map<int, NodeValues> by_node(const Stencil<N>& s) {
  std::map<int, NodeValues> out;
  for (int k = 0; k < s.count; ++k) {
    if (s.weight[k] == 0.0 && s.gradient[k].isZero(0.0)) continue;
    out[s.node[k]].weight += s.weight[k];
    out[s.node[k]].gradient += s.gradient[k];
  }
  return out;
}

template <class Shape>
std::map<int, NodeValues> stencil_of(const GridGeometry& grid, const Particles& P, std::size_t p = 0) {
  const Shape shape = Shape::bind(grid, P);
  Stencil<Shape::stencil_size> s;
  shape.evaluate(p, s);
  return by_node(s);
}

// Two stencils list the same nodes with the same weights and gradients.
void expect_same_stencil(const std::map<int, NodeValues>& got, const std::map<int, NodeValues>& expected, double h) {
  ASSERT_EQ(got.size(), expected.size());
  for (const auto& [node, e] : expected) {
    ASSERT_TRUE(got.count(node)) << "node " << node;
    EXPECT_NEAR(got.at(node).weight, e.weight, 1e-14);
    EXPECT_LT((got.at(node).gradient - e.gradient).norm() * h, 1e-13);
  }
}

// The tent of node (i, j) and its gradient at x, straight from its definition.
double tent(const GridGeometry& g, int i, int j, const Vec2& x, Vec2* gradient) {
  const Vec2 d = (x - g.node_position(i, j)) / g.h;
  const double ax = std::abs(d.x()), ay = std::abs(d.y());
  if (ax >= 1.0 || ay >= 1.0) {
    *gradient = Vec2::Zero();
    return 0.0;
  }
  const double sx = d.x() < 0.0 ? 1.0 : -1.0, sy = d.y() < 0.0 ? 1.0 : -1.0;
  *gradient = Vec2(sx * (1.0 - ay), sy * (1.0 - ax)) / g.h;
  return (1.0 - ax) * (1.0 - ay);
}

TEST(PolygonMoments, UnitSquareAndTriangle) {
  const Vec2 square[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const mpmvv::PolygonMoments s = mpmvv::polygon_moments(square, 4);
  EXPECT_NEAR(s.area, 1.0, 1e-15);
  EXPECT_NEAR(s.u, 0.5, 1e-15);
  EXPECT_NEAR(s.v, 0.5, 1e-15);
  EXPECT_NEAR(s.uv, 0.25, 1e-15);
  // int over the triangle u, v >= 0, u + v <= 1: 1/2, 1/6, 1/6, 1/24.
  const Vec2 triangle[3] = {{0, 0}, {1, 0}, {0, 1}};
  const mpmvv::PolygonMoments t = mpmvv::polygon_moments(triangle, 3);
  EXPECT_NEAR(t.area, 0.5, 1e-15);
  EXPECT_NEAR(t.u, 1.0 / 6.0, 1e-15);
  EXPECT_NEAR(t.v, 1.0 / 6.0, 1e-15);
  EXPECT_NEAR(t.uv, 1.0 / 24.0, 1e-15);
}

// For random sheared and stretched domains that cross cell lines, S_gp and
// G_gp equal the averages of the tents over the domain, taken by a midpoint
// rule on 800 x 800 points of the parallelogram (error ~1e-6 at the kinks).
TEST(CpdiExactShape, WeightsAndGradientsAreTheAveragesOverTheDomain) {
  const GridGeometry grid = grid_of(0.25);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> where(4.0, 8.0), size(0.15, 0.45);
  double worst_weight = 0.0, worst_gradient = 0.0, corner_formula_gap = 0.0;
  for (int trial = 0; trial < 12; ++trial) {
    const Mat2 F = mpmvv::testing::random_deformation(rng, 0.5, 0.4);
    const Vec2 x = grid.origin + grid.h * Vec2(where(rng), where(rng));
    const Particles P = one_particle(x, F, grid.h * Vec2(size(rng), size(rng)));
    const std::map<int, NodeValues> exact = stencil_of<CpdiExactShape>(grid, P);
    Mat2 s = F;
    s.col(0) *= P.half_size[0].x();
    s.col(1) *= P.half_size[0].y();
    const int n = 800;
    std::map<int, NodeValues> reference;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        const Vec2 y = x + s * Vec2(-1.0 + (2.0 * a + 1.0) / n, -1.0 + (2.0 * b + 1.0) / n);
        const Vec2 xi = (y - grid.origin) / grid.h;
        const int i = int(std::floor(xi.x())), j = int(std::floor(xi.y()));
        for (int dj = 0; dj <= 1; ++dj)
          for (int di = 0; di <= 1; ++di) {
            Vec2 gradient;
            const double w = tent(grid, i + di, j + dj, y, &gradient);
            NodeValues& r = reference[grid.node(i + di, j + dj)];
            r.weight += w / double(n * n);
            r.gradient += gradient / double(n * n);
          }
      }
    for (const auto& [node, r] : reference) {
      const NodeValues got = exact.count(node) ? exact.at(node) : NodeValues{};
      worst_weight = std::max(worst_weight, std::abs(got.weight - r.weight));
      worst_gradient = std::max(worst_gradient, (got.gradient - r.gradient).norm() * grid.h);
    }
    for (const auto& [node, got] : exact) EXPECT_TRUE(reference.count(node) || got.weight == 0.0);
    // The corner formula of CPDI differs where the domain crosses a cell line.
    const std::map<int, NodeValues> corners = stencil_of<CpdiShape>(grid, P);
    for (const auto& [node, r] : reference) {
      const NodeValues c = corners.count(node) ? corners.at(node) : NodeValues{};
      corner_formula_gap = std::max(corner_formula_gap, std::abs(c.weight - r.weight));
    }
  }
  EXPECT_LT(worst_weight, 2e-5);
  EXPECT_LT(worst_gradient, 2e-5);
  // ... by far more than the quadrature's own error: the test can tell them apart.
  EXPECT_GT(corner_formula_gap, 1e-3);
}

// Inside one cell the grid basis is bilinear. Its average gradient over a
// parallelogram is exactly what the corner formula of CPDI gives (eq. 1.100),
// so the gradients agree to round-off. The weights do not: the corner mean
// of the basis's u v term is (r1x r1y + r2x r2y) / h^2 where the domain's mean
// is a third of that, so exact minus corner is -(2/3)(r1x r1y + r2x r2y) / h^2
// times the sign of the node's u v coefficient (+ at (0,0) and (1,1)).
TEST(CpdiExactShape, AgreesWithTheCornerFormulaInsideOneCell) {
  const GridGeometry grid = grid_of(0.5);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> offset(-0.05, 0.05);
  for (int trial = 0; trial < 20; ++trial) {
    const Mat2 F = mpmvv::testing::random_deformation(rng, 0.3, 0.5);
    const Vec2 centre = grid.origin + grid.h * Vec2(5.5 + offset(rng), 6.5 + offset(rng));
    const Particles P = one_particle(centre, F, grid.h * Vec2(0.12, 0.1));
    ASSERT_TRUE(CpdiExactShape::bind(grid, P).inside(0));
    // The stencil lists the cell's four nodes only, not the block's 16.
    Stencil<CpdiExactShape::stencil_size> listed;
    CpdiExactShape::bind(grid, P).evaluate(0, listed);
    EXPECT_EQ(listed.count, 4);
    const std::map<int, NodeValues> exact = stencil_of<CpdiExactShape>(grid, P);
    const std::map<int, NodeValues> corners = stencil_of<CpdiShape>(grid, P);
    ASSERT_EQ(exact.size(), corners.size());
    const Vec2 r1 = F.col(0) * P.half_size[0].x(), r2 = F.col(1) * P.half_size[0].y();
    const double quadratic = -(2.0 / 3.0) * (r1.x() * r1.y() + r2.x() * r2.y()) / (grid.h * grid.h);
    for (const auto& [node, c] : corners) {
      ASSERT_TRUE(exact.count(node));
      const Vec2 d = (grid.node_position(node % grid.nodes_x(), node / grid.nodes_x()) - centre) / grid.h;
      const double sign = d.x() * d.y() > 0.0 ? 1.0 : -1.0;  // (0,0) and (1,1) lie on the diagonal through the centre
      EXPECT_NEAR(exact.at(node).weight - c.weight, sign * quadratic, 1e-13);
      EXPECT_LT((exact.at(node).gradient - c.gradient).norm() * grid.h, 1e-12);
    }
  }
}

// An outline of the parallelogram's own four corners gives the same stencil.
TEST(CpdiExactShape, OutlineOfTheParallelogramChangesNothing) {
  const GridGeometry grid = grid_of(0.25);
  Mat2 F;
  F << 1.1, 0.4, -0.2, 0.9;
  const Vec2 l(0.09, 0.07);
  Particles P = one_particle(grid.origin + Vec2(1.37, 1.52), F, l);
  const std::map<int, NodeValues> before = stencil_of<CpdiExactShape>(grid, P);
  P.domain_first = {0, 4};
  P.domain_vertex = {Vec2(-l.x(), -l.y()), Vec2(l.x(), -l.y()), Vec2(l.x(), l.y()), Vec2(-l.x(), l.y())};
  expect_same_stencil(stencil_of<CpdiExactShape>(grid, P), before, grid.h);
}

// Two pieces on a bridge (a square and a triangle apart from it, across a
// cell line) integrate as the area-weighted mean of the two pieces alone.
TEST(CpdiExactShape, BridgedPiecesIntegrateAsThePiecesDo) {
  const GridGeometry grid = grid_of(0.25);
  Mat2 F;
  F << 0.95, 0.2, 0.1, 1.05;
  const Vec2 x = grid.origin + Vec2(1.52, 1.48);
  const std::vector<Vec2> square = {{-0.05, -0.05}, {0.03, -0.05}, {0.03, 0.03}, {-0.05, 0.03}};
  const std::vector<Vec2> triangle = {{0.06, -0.02}, {0.12, -0.02}, {0.06, 0.08}};
  auto with_outline = [&](const std::vector<Vec2>& outline) {
    Particles P = one_particle(x, F, Vec2(0.05, 0.05));
    P.domain_first = {0, std::uint32_t(outline.size())};
    P.domain_vertex = outline;
    return stencil_of<CpdiExactShape>(grid, P);
  };
  std::vector<Vec2> both = square;
  both.push_back(square.front());
  both.insert(both.end(), triangle.begin(), triangle.end());
  both.push_back(triangle.front());
  const double a_square = 0.08 * 0.08, a_triangle = 0.5 * 0.06 * 0.1;
  const std::map<int, NodeValues> joined = with_outline(both), s = with_outline(square), t = with_outline(triangle);
  std::map<int, NodeValues> expected;
  for (const auto& [node, v] : s) {
    expected[node].weight += v.weight * a_square / (a_square + a_triangle);
    expected[node].gradient += v.gradient * a_square / (a_square + a_triangle);
  }
  for (const auto& [node, v] : t) {
    expected[node].weight += v.weight * a_triangle / (a_square + a_triangle);
    expected[node].gradient += v.gradient * a_triangle / (a_square + a_triangle);
  }
  for (const auto& [node, e] : expected) {
    const NodeValues got = joined.count(node) ? joined.at(node) : NodeValues{};
    EXPECT_NEAR(got.weight, e.weight, 1e-13);
    EXPECT_LT((got.gradient - e.gradient).norm() * grid.h, 1e-12);
  }
}

// A domain stretched over more than three cells leaves the stencil's 4 x 4
// nodes: `inside` says so, and the run stops there instead of losing mass.
TEST(CpdiExactShape, DomainBeyondThreeCellsIsNotInside) {
  const GridGeometry grid = grid_of(0.25);
  Mat2 stretch;
  stretch << 6.5, 0.0, 0.0, 1.0;
  const Vec2 x = grid.origin + grid.h * Vec2(6.0, 6.0);
  const Particles fits = one_particle(x, Mat2::Identity(), grid.h * Vec2(0.25, 0.25));
  const Particles too_long = one_particle(x, stretch, grid.h * Vec2(0.25, 0.25));  // 3.25 cells long
  EXPECT_TRUE(CpdiExactShape::bind(grid, fits).inside(0));
  EXPECT_FALSE(CpdiExactShape::bind(grid, too_long).inside(0));
}

// Corner domains (cpdi_domain = "corners"): the particle's own four corners.
using CornerExactShape = mpmvv::CpdiExactShapeT<mpmvv::Geometry::plane_strain, true>;

Particles with_corners(const Particles& base, const std::vector<Vec2>& corners) {
  Particles P = base;
  P.domain_corner = corners;
  return P;
}

// A quadrilateral that is no parallelogram (one reflex corner, across two
// cell lines) integrates exactly as the outline of the same four points does,
// and a parallelogram's corners as the parallelogram F_p diag(l_p).
TEST(CpdiExactShape, CornerDomainIntegratesItsQuadrilateral) {
  const GridGeometry grid = grid_of(0.25);
  Mat2 F;
  F << 1.1, 0.4, -0.2, 0.9;
  const Vec2 l(0.09, 0.07);
  const Particles P = one_particle(grid.origin + Vec2(1.37, 1.52), F, l);
  mpmvv::Particles started = P;
  mpmvv::start_domain_corners(started);
  expect_same_stencil(stencil_of<CornerExactShape>(grid, started), stencil_of<CpdiExactShape>(grid, P), grid.h);
  const Vec2 x = P.position[0];
  // Counter-clockwise, the corner at (+,+) pulled in past the diagonal: reflex.
  const std::vector<Vec2> quad = {x + Vec2(-0.1, -0.08), x + Vec2(0.12, -0.06), x + Vec2(-0.01, 0.0),
                                  x + Vec2(-0.09, 0.11)};
  const Particles reflex = with_corners(P, quad);
  const CornerExactShape shape = CornerExactShape::bind(grid, reflex);
  EXPECT_TRUE(shape.inside(0));
  EXPECT_FALSE(CornerExactShape::crossed(quad.data()));
  Particles outlined = P;
  outlined.deformation_gradient[0] = Mat2::Identity();
  outlined.domain_first = {0, 4};
  for (const Vec2& c : quad) outlined.domain_vertex.push_back(c - x);
  expect_same_stencil(stencil_of<CornerExactShape>(grid, reflex), stencil_of<CpdiExactShape>(grid, outlined), grid.h);
}

// A bow tie (corners 2 and 3 swapped past each other, positive signed area
// left) integrates as the parallelogram a_0 +- a_1 +- a_2 of its linear part.
// A quadrilateral turned over (clockwise) is folded: its particle integrates
// over its own parallelogram x_p + F_p A_p, as the parallelogram form does,
// stays inside, and the monitors count it.
TEST(CpdiExactShape, CrossedCornerDomainTakesItsParallelogramAndATurnedOneItsParticles) {
  const GridGeometry grid = grid_of(0.25);
  Mat2 F;
  F << 1.1, 0.6, -0.2, 0.9;
  Particles P = one_particle(grid.origin + Vec2(1.37, 1.52), F, Vec2(0.08, 0.06));
  P.mass[0] = 1.0;
  const Vec2 x = P.position[0];
  const std::vector<Vec2> bow = {x + Vec2(-0.1, -0.04), x + Vec2(0.12, -0.04), x + Vec2(-0.02, 0.04),
                                 x + Vec2(0.06, 0.02)};
  ASSERT_TRUE(CornerExactShape::crossed(bow.data()));
  const Mat2 s = mpmvv::corner_half_vectors(bow.data());
  ASSERT_GT(mpmvv::determinant(s), 0.0);
  const Vec2 a0 = 0.25 * (bow[0] + bow[1] + bow[2] + bow[3]);
  std::vector<Vec2> parallelogram;
  for (int c = 0; c < 4; ++c) parallelogram.push_back(a0 + mpmvv::kCornerXi[c] * s.col(0) + mpmvv::kCornerEta[c] * s.col(1));
  expect_same_stencil(stencil_of<CornerExactShape>(grid, with_corners(P, bow)),
                      stencil_of<CornerExactShape>(grid, with_corners(P, parallelogram)), grid.h);
  const mpmvv::NeoHookean material{577.0, 385.0};
  const Particles bowed = with_corners(P, bow);
  const CornerExactShape crossed = CornerExactShape::bind(grid, bowed);
  EXPECT_FALSE(crossed.folded(0));
  EXPECT_TRUE(crossed.inside(0));
  EXPECT_EQ(mpmvv::monitor_particles(crossed, material, bowed, grid).folded_domains, 0u);

  const std::vector<Vec2> turned = {parallelogram[0], parallelogram[3], parallelogram[2], parallelogram[1]};
  const Particles turned_over = with_corners(P, turned);
  const CornerExactShape over = CornerExactShape::bind(grid, turned_over);
  EXPECT_TRUE(over.folded(0));
  EXPECT_TRUE(over.inside(0));
  const Mat2 own = F * Vec2(0.08, 0.06).asDiagonal();
  EXPECT_TRUE(over.domain(0).isApprox(own, 1e-15)) << over.domain(0);
  expect_same_stencil(stencil_of<CornerExactShape>(grid, turned_over), stencil_of<CpdiExactShape>(grid, P), grid.h);
  EXPECT_EQ(mpmvv::monitor_particles(over, material, turned_over, grid).folded_domains, 1u);
  // The corner interpolation keeps the turned quadrilateral and is counted alike.
  using CornerShape = mpmvv::CpdiShapeT<mpmvv::Geometry::plane_strain, mpmvv::CpdiForm::corners>;
  EXPECT_EQ(mpmvv::monitor_particles(CornerShape::bind(grid, turned_over), material, turned_over, grid).folded_domains,
            1u);
  EXPECT_EQ(mpmvv::monitor_particles(CornerShape::bind(grid, bowed), material, bowed, grid).folded_domains, 0u);
}

// USL's stored stencils (stored_stencils.hpp): a map through the recorder
// gives the grid what the shape itself gives and keeps every particle's
// stencil; an update through the reader then moves, deforms and turns the
// particles exactly as one through the shape does. Sheared corner domains
// across cell lines, under APIC, with a random grid velocity.
TEST(StoredStencils, RecordedMapAndReadUpdateAreTheShapesOwn) {
  const GridGeometry grid = grid_of(0.25);
  Mat2 F;
  F << 1.2, 0.7, -0.1, 0.9;
  Particles P;
  const int n = 12;
  P.resize(n);
  P.half_size.assign(n, Vec2(0.06, 0.05));
  P.affine_velocity.assign(n, Mat2::Zero());
  std::mt19937 random(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int p = 0; p < n; ++p) {
    P.position[p] = P.reference_position[p] = grid.origin + Vec2(1.1 + 0.13 * p, 1.3 + 0.07 * p);
    P.deformation_gradient[p] = F;
    P.reference_volume[p] = 4.0 * 0.06 * 0.05;
    P.volume[p] = mpmvv::determinant(F) * P.reference_volume[p];
    P.mass[p] = 1.0 + 0.1 * p;
    P.velocity[p] = Vec2(u(random), u(random));
    P.affine_velocity[p] << u(random), u(random), u(random), u(random);
    P.stress[p] << 10.0 * u(random), u(random), u(random), 10.0 * u(random);
  }
  mpmvv::start_domain_corners(P);
  const CornerExactShape shape = CornerExactShape::bind(grid, P);
  std::vector<mpmvv::Stencil<CornerExactShape::stencil_size>> store(P.size());
  const std::size_t nodes = grid.node_count();
  mpmvv::ScatterBuffers buffers;
  buffers.resize(mpmvv::max_threads(), nodes);
  constexpr unsigned kMap = mpmvv::kMass | mpmvv::kMomentum | mpmvv::kInternalForce | mpmvv::kAffineMomentum;
  mpmvv::GridFields direct, recorded;
  direct.resize(nodes);
  recorded.resize(nodes);
  mpmvv::particles_to_grid<kMap>(shape, P, buffers, direct, {}, &grid);
  mpmvv::particles_to_grid<kMap>(mpmvv::StencilRecorder<CornerExactShape>{shape, store.data()}, P, buffers, recorded,
                                 {}, &grid);
  EXPECT_EQ(direct.mass, recorded.mass);
  EXPECT_EQ(direct.momentum, recorded.momentum);
  EXPECT_EQ(direct.force, recorded.force);
  for (std::size_t p = 0; p < P.size(); ++p) expect_same_stencil(by_node(store[p]), stencil_of<CornerExactShape>(grid, P, p), grid.h);

  for (std::size_t k = 0; k < nodes; ++k) direct.velocity[k] = direct.acceleration[k] = Vec2(u(random), u(random));
  constexpr unsigned kUpdate = mpmvv::kVelocity | mpmvv::kPosition | mpmvv::kDeformation | mpmvv::kAffine;
  Particles by_shape = P, by_store = P;
  mpmvv::grid_to_particles<kUpdate>(shape, direct, by_shape, 0.01, 0.01);
  mpmvv::grid_to_particles<kUpdate>(mpmvv::StencilReader<CornerExactShape>{shape, store.data()}, direct, by_store,
                                    0.01, 0.01);
  EXPECT_EQ(by_shape.position, by_store.position);
  EXPECT_EQ(by_shape.velocity, by_store.velocity);
  EXPECT_EQ(by_shape.deformation_gradient, by_store.deformation_gradient);
  EXPECT_EQ(by_shape.affine_velocity, by_store.affine_velocity);
  EXPECT_NE(by_shape.position, P.position);  // the update moved them
}

}  // namespace
