// CPDI corner domains (solver/domain_corners.hpp): a parallelogram weighs the
// grid as the convected domain, a quadrilateral as the mean of the hats, the
// corners follow an affine grid motion, neighbours keep sharing corners under
// shear and split halves share the cut edge.
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

}  // namespace
