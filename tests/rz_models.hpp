// What the r-z tests share (test_axisymmetric.cpp, test_axisymmetric_cpdi.cpp,
// test_axisymmetric_step.cpp): an r-z grid with walls on the axis, particles
// at test positions, the sums of a stencil and the properties every r-z shape
// function has (with the round-off they hold to).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "solver/explicit_stepper.hpp"
#include "support.hpp"
#include "solver/particles.hpp"
#include "solver/shape/cpdi.hpp"
#include "solver/shape/cpdi_exact.hpp"
#include "solver/shape/gimp.hpp"
#include "solver/shape/linear.hpp"
#include "solver/stages.hpp"

namespace mpmvv::testing::rz_models {

using mpmvv::CpdiExactShapeT;
using mpmvv::CpdiShapeT;
using mpmvv::Geometry;
using mpmvv::GimpShapeT;
using mpmvv::GridFields;
using mpmvv::GridGeometry;
using mpmvv::LinearShapeT;
using mpmvv::Mat2;
using mpmvv::Method;
using mpmvv::Model;
using mpmvv::NeoHookean;
using mpmvv::Particles;
using mpmvv::Scheme;
using mpmvv::SolverOptions;
using mpmvv::Stencil;
using mpmvv::Vec2;

inline constexpr Geometry kRz = Geometry::axisymmetric;

// Walls at r = 0, z = 0 and r = z = 2 m, one ghost layer beyond each:
// nodes from -0.25 to 2.25 along both axes.
inline GridGeometry rz_grid() { return GridGeometry::walled(Vec2(0.0, 0.0), 0.25, 8, 8); }

// Two particles per cell per direction: half-size h/4.
inline constexpr double kHalfSize = 0.0625;

inline Particles particles_at(const std::vector<Vec2>& positions, const Mat2& F = Mat2::Identity()) {
  Particles P;
  P.resize(positions.size());
  P.half_size.assign(positions.size(), Vec2(kHalfSize, kHalfSize));
  P.hoop_stretch.assign(positions.size(), 1.0);
  P.hoop_stress.assign(positions.size(), 0.0);
  for (std::size_t p = 0; p < positions.size(); ++p) {
    P.position[p] = P.reference_position[p] = positions[p];
    P.deformation_gradient[p] = F;
  }
  return P;
}

// Random interior positions, positions whose support reaches the ghost layer
// beyond the axis (r_p <= l: the particle domain touches or crosses r = 0),
// beyond z = 0 and beyond the upper walls, and the corners of both.
inline std::vector<Vec2> test_positions() {
  std::vector<Vec2> x = {{0.0625, 1.0}, {0.04, 1.0},  {0.1, 0.03},   {0.9, 0.03},  {0.9, 1.98},
                         {1.98, 0.7},   {1.98, 1.98}, {0.05, 0.05},  {0.3, 0.125}, {0.125, 0.5},
                         {1.0, 1.0},    {0.25, 0.25}, {1.875, 1.99}, {0.0625, 0.0625}};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.3, 1.7);
  for (int k = 0; k < 40; ++k) x.emplace_back(u(rng), u(rng));
  return x;
}

// Sheared and stretched CPDI domains: simple shear, stretch with rotation, and
// a compressed one.
inline std::vector<Mat2> cpdi_deformations() {
  Mat2 stretch;
  stretch << 1.3, 0.0, 0.0, 0.8;
  Mat2 general;
  general << 1.2, 0.3, -0.2, 0.9;
  return {Mat2::Identity(), mpmvv::testing::simple_shear(0.6), mpmvv::testing::rotation(0.5) * stretch, general};
}

inline Vec2 node_position(const GridGeometry& grid, int node) {
  return grid.node_position(node % grid.nodes_x(), node / grid.nodes_x());
}

// The sums properties (a)-(f) are stated in.
struct Sums {
  double weight = 0.0;                      // sum_k w_k
  Vec2 gradient = Vec2::Zero();             // sum_k G_k
  Mat2 completeness = Mat2::Zero();         // sum_k x_k (outer) G_k
  double hoop = 0.0;                        // sum_k <S_k / r>
  double hoop_times_radius = 0.0;           // sum_k <S_k / r> r_k
  Vec2 centroid = Vec2::Zero();             // sum_k w_k x_k
};

template <class Shape>
inline Sums stencil_sums(const GridGeometry& grid, const Shape& shape, std::size_t p) {
  Stencil<Shape::stencil_size> s;
  shape.evaluate(p, s);
  Sums sums;
  for (int k = 0; k < s.count; ++k) {
    const Vec2 x = node_position(grid, s.node[k]);
    sums.weight += s.weight[k];
    sums.gradient += s.gradient[k];
    sums.completeness += x * s.gradient[k].transpose();
    sums.hoop += s.hoop[k];
    sums.hoop_times_radius += s.hoop[k] * x.x();
    sums.centroid += s.weight[k] * x;
  }
  return sums;
}

// The r-weighted centroid of particle p's domain, property (f).
inline Vec2 linear_centroid(const Particles& P, std::size_t p) { return P.position[p]; }
inline Vec2 gimp_centroid(const Particles& P, std::size_t p) {
  const double r = P.position[p].x(), l = P.half_size[p].x();
  return {r + l * l / (3.0 * r), P.position[p].y()};  // int r'^2 dr' / int r' dr' over [r - l, r + l]
}
inline Vec2 cpdi_centroid(const Particles& P, std::size_t p) {
  Mat2 s = P.deformation_gradient[p];
  s.col(0) *= P.half_size[p].x();
  s.col(1) *= P.half_size[p].y();
  const double r = P.position[p].x();
  // x = x_p + xi r1 + eta r2, weight r = r_p + a xi + b eta, xi, eta uniform on [-1, 1].
  return P.position[p] + (s(0, 0) * s.col(0) + s(0, 1) * s.col(1)) / (3.0 * r);
}

// Sums of at most 16 products of numbers of order one (weights), 1/h
// (gradients) or 1/r_p <= 25 (hoop): round-off is a few 1e-16 relative;
// measured worst 5.7e-15 (CPDI with deformed domains next to the axis).
// 1e-12 relative to the size of the sum leaves two orders of margin.
inline constexpr double kRoundOff = 1e-12;

template <class Shape>
inline void expect_rz_properties(const GridGeometry& grid, const Particles& P, Vec2 (*centroid)(const Particles&, std::size_t),
                          const std::string& label, double& worst) {
  const Shape shape = Shape::bind(grid, P);
  for (std::size_t p = 0; p < P.size(); ++p) {
    ASSERT_TRUE(shape.inside(p)) << label << " x = " << P.position[p].transpose();
    const Sums s = stencil_sums(grid, shape, p);
    const double r = P.position[p].x();
    const std::string where = label + " x = (" + std::to_string(P.position[p].x()) + ", " +
                              std::to_string(P.position[p].y()) + ")";
    const double errors[] = {
        std::abs(s.weight - 1.0),                                      // (a)
        s.gradient.norm() * grid.h,                                    // (b)
        (s.completeness - Mat2::Identity()).cwiseAbs().maxCoeff(),     // (c)
        std::abs(s.hoop_times_radius - 1.0),                           // (d)
        std::abs(s.hoop * r - 1.0),                                    // (e)
        (s.centroid - centroid(P, p)).norm() / grid.h,                 // (f)
    };
    const char* names[] = {"(a) sum w = 1", "(b) sum G = 0", "(c) sum x G^T = I", "(d) sum <S/r> r_g = 1",
                           "(e) sum <S/r> = 1 / r_p", "(f) sum w x_g = r-weighted centroid"};
    for (int k = 0; k < 6; ++k) {
      worst = std::max(worst, errors[k]);
      EXPECT_LE(errors[k], kRoundOff) << names[k] << " " << where;
    }
  }
}

}  // namespace mpmvv::testing::rz_models
