// CPDI with parallelogram particle domains (002_c3305cb8b1bc1490.txt section
// 1.6.4, eqs. 1.94-1.100, in 2D). The domain of particle p is spanned by
// r_1 = F_p (l_x e_x) and r_2 = F_p (l_y e_y) about its centroid (eq. 1.97);
// the grid basis is interpolated bilinearly from its four corners (eq. 1.95),
// which gives
//   S_gp = (1/4) sum_c S_g(x_c),
//   G_gp = (1/4) s_p^-T sum_c (xi_c, eta_c)^T S_g(x_c),   s_p = [r_1 r_2],
// the 2D form of eq. 1.100 (the mean over the square of dN_c/dxi is xi_c / 4).
//
// In r-z the averages carry the weight r = r_p + a xi + b eta over the domain
// (a, b the radial components of r_1, r_2); integrating the corner functions
// exactly:
//   S_gp  = sum_c (1/4)(1 + (a xi_c + b eta_c) / (3 r_p)) S_g(x_c),
//   G_gp  = s_p^-T sum_c ((xi_c/4)(1 + b eta_c / (3 r_p)), (eta_c/4)(1 + a xi_c / (3 r_p))) S_g(x_c),
//   <S/r> = (1 / (4 r_p)) sum_c S_g(x_c).
#pragma once

#include <cstddef>

#include "../particles.hpp"
#include "linear.hpp"
#include "stencil.hpp"

namespace mpmvv {

template <Geometry G>
struct CpdiShapeT {
  static constexpr int stencil_size = 16;  // four nodes for each of four corners
  static constexpr const char* name = "cpdi";
  static constexpr Geometry geometry = G;
  static constexpr bool reads_deformation_gradient = true;

  // Natural coordinates of the corners, counter-clockwise (eq. 1.99 in 2D).
  static constexpr double corner_xi[4] = {-1.0, 1.0, 1.0, -1.0};
  static constexpr double corner_eta[4] = {-1.0, -1.0, 1.0, 1.0};

  const GridGeometry* grid;
  const Vec2* position;
  const Mat2* deformation_gradient;
  const Vec2* half_size;
  double gradient_scale;  // 1, but for a deliberate fault (SolverOptions::cpdi_gradient_scale)

  // The domains span F_p diag(l_p); `deformation_gradient` may point to a copy
  // of F taken at the start of a step, so that every transfer of the step uses
  // the same domains.
  static CpdiShapeT bind(const GridGeometry& grid, const Particles& particles,
                         const Mat2* deformation_gradient = nullptr, double gradient_scale = 1.0) {
    return {&grid, particles.position.data(),
            deformation_gradient ? deformation_gradient : particles.deformation_gradient.data(),
            particles.half_size.data(), gradient_scale};
  }

  // s_p = [r_1 r_2], the current domain half-vectors as columns (eq. 1.97).
  Mat2 domain(std::size_t p) const {
    Mat2 s = deformation_gradient[p];
    s.col(0) *= half_size[p].x();
    s.col(1) *= half_size[p].y();
    return s;
  }

  Vec2 corner(std::size_t p, const Mat2& s, int c) const {
    return position[p] + corner_xi[c] * s.col(0) + corner_eta[c] * s.col(1);
  }

  void evaluate(std::size_t p, Stencil<stencil_size>& st) const {
    const Mat2 s = domain(p);
    // s^-T = [[s11, -s10], [-s01, s00]] / det s.
    const double inv_det = gradient_scale / determinant(s);
    double weight_r = 0.0, weight_a = 0.0, weight_b = 0.0;
    if constexpr (G == Geometry::axisymmetric) {
      weight_r = 1.0 / (3.0 * position[p].x());
      weight_a = s(0, 0) * weight_r;
      weight_b = s(0, 1) * weight_r;
    }
    for (int c = 0; c < 4; ++c) {
      const double xi = corner_xi[c], eta = corner_eta[c];
      double corner_weight = 0.25, gxi = 0.25 * xi, geta = 0.25 * eta;
      if constexpr (G == Geometry::axisymmetric) {
        corner_weight *= 1.0 + weight_a * xi + weight_b * eta;
        gxi *= 1.0 + weight_b * eta;
        geta *= 1.0 + weight_a * xi;
      }
      const Vec2 corner_gradient = inv_det * Vec2(s(1, 1) * gxi - s(1, 0) * geta, s(0, 0) * geta - s(0, 1) * gxi);
      int* node = st.node + 4 * c;
      double* w = st.weight + 4 * c;
      bilinear_cell_weights(*grid, corner(p, s, c), node, w);
      for (int k = 0; k < 4; ++k) {
        st.gradient[4 * c + k] = corner_gradient * w[k];
        if constexpr (G == Geometry::axisymmetric) st.hoop[4 * c + k] = 0.75 * weight_r * w[k];
        w[k] *= corner_weight;
      }
    }
  }

  // The centre lies between the walls (in r-z off the axis) and every corner
  // of the domain in the grid (ghost layers included).
  bool inside(std::size_t p) const {
    if constexpr (G == Geometry::axisymmetric)
      if (!(position[p].x() > 0.0)) return false;
    if (!inside_walls(*grid, position[p])) return false;
    // The corners x_p +- r_1 +- r_2 reach |r_1| + |r_2| along each axis: their
    // bounding box, without forming the four corners (the scan runs every step).
    const Vec2 reach = domain(p).cwiseAbs().rowwise().sum();
    return inside_cells(*grid, grid_coordinate(*grid, position[p] - reach)) &&
           inside_cells(*grid, grid_coordinate(*grid, position[p] + reach));
  }
};

using CpdiShape = CpdiShapeT<Geometry::plane_strain>;

}  // namespace mpmvv
