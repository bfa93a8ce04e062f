// CPDI with parallelogram particle domains (002_c3305cb8b1bc1490.txt section
// 1.6.4, eqs. 1.94-1.100, in 2D). The domain of particle p is spanned by
// r_1 = F_p (l_x e_x) and r_2 = F_p (l_y e_y) about its centroid (eq. 1.97),
// or by the columns of F_p A_p once its domain has been turned (domain_angle.hpp);
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
//
// With corner domains (domain_corners.hpp, plane strain) the domain is the
// quadrilateral of its four corners x_c, x = a_0 + a_1 xi + a_2 eta + a_3 xi eta,
// whose Jacobian is det J = J0 + J1 xi + J2 eta (J0 = a_1 x a_2,
// J1 = a_1 x a_3, J2 = a_3 x a_2) and area 4 J0. The bilinear corner function
// phi_c integrates over it to J0 + (J1 xi_c + J2 eta_c) / 3 and its gradient
// to (1/2) rot(x_{c+1} - x_{c-1}), rot(a) = (a_y, -a_x) (the divergence
// theorem over the corner's two edges), which gives
//   S_gp = sum_c (1/4)(1 + (J1 xi_c + J2 eta_c) / (3 J0)) S_g(x_c),
//   G_gp = (1 / (8 J0)) sum_c rot(x_{c+1} - x_{c-1}) S_g(x_c);
// for a parallelogram (a_3 = 0) these are the two lines above.
//
// This file holds the domain itself: its vectors s_p, its corners, the corner
// factors of S_gp and G_gp above, and the tests a health scan asks of it
// (inside, folded). cpdi.hpp reads the grid basis at the corners with them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "../domain_corners.hpp"
#include "../particles.hpp"
#include "stencil.hpp"

namespace mpmvv {

// The domain's form, chosen once per run, not once per particle:
enum class CpdiForm {
  convected,  // F_p diag(l_p)
  turned,     // F_p A_p (Particles::domain_axes), held open under shear (domain_angle.hpp)
  corners,    // the quadrilateral of Particles::domain_corner (domain_corners.hpp)
};

// The domain of each particle, read from the particle arrays it points to.
template <Geometry G, CpdiForm Form = CpdiForm::convected>
struct CpdiDomainT {
  static constexpr bool Turned = Form == CpdiForm::turned;
  static constexpr bool Corners = Form == CpdiForm::corners;
  static_assert(!Corners || G == Geometry::plane_strain, "corner domains are plane strain only");

  // Natural coordinates of the corners, counter-clockwise (eq. 1.99 in 2D).
  static constexpr const double (&corner_xi)[4] = kCornerXi;
  static constexpr const double (&corner_eta)[4] = kCornerEta;

  const GridGeometry* grid;
  const Vec2* position;
  const Mat2* deformation_gradient;
  const Vec2* half_size;
  const Mat2* domain_axes;  // Turned: A_p; else null, and the domains span diag(half_size)
  double gradient_scale;  // 1, but for a deliberate fault (faults.hpp: cpdi-gradient)
  const Vec2* corners;    // Corners: x_pc, four per particle (Particles::domain_corner); else null
  // 0, but for a deliberate fault (faults.hpp: cpdi-weight): the corner
  // shares of S_gp are (1/4)(1 + weight_skew xi_c). Parallelogram domains only.
  double weight_skew = 0.0;
  // 1, but for a deliberate fault (faults.hpp: cpdi-shear-sign): the sign of
  // the cross terms s10, s01 of s^-T, which only a sheared (or turned)
  // domain has. Parallelogram domains only.
  double shear_sign = 1.0;

  // s_p = [r_1 r_2], the current domain half-vectors as columns (eq. 1.97);
  // for corner domains the linear part [a_1 a_2] of their map.
  Mat2 domain(std::size_t p) const {
    if constexpr (Corners) return corner_half_vectors(corners + 4 * p);
    Mat2 s = deformation_gradient ? deformation_gradient[p] : Mat2::Identity();
    if constexpr (Turned) {
      return s * domain_axes[p];
    } else {
      s.col(0) *= half_size[p].x();
      s.col(1) *= half_size[p].y();
      return s;
    }
  }

  Vec2 corner(std::size_t p, const Mat2& s, int c) const {
    if constexpr (Corners) return corners[4 * p + c];
    return position[p] + corner_xi[c] * s.col(0) + corner_eta[c] * s.col(1);
  }

  // Corner domains: the corner factors of S_gp and G_gp (above), given the
  // quadrilateral's linear part s = domain(p), which every caller has formed.
  void quadrilateral_factors(std::size_t p, const Mat2& s, double* weight, double* gradient_x,
                             double* gradient_y) const {
    const Vec2* x = corners + 4 * p;
    const double a3x = 0.25 * (x[0].x() - x[1].x() + x[2].x() - x[3].x());
    const double a3y = 0.25 * (x[0].y() - x[1].y() + x[2].y() - x[3].y());
    const double J0 = determinant(s);
    const double J1 = s(0, 0) * a3y - s(1, 0) * a3x;
    const double J2 = a3x * s(1, 1) - a3y * s(0, 1);
    const double inv = gradient_scale / (8.0 * J0);
    for (int c = 0; c < 4; ++c) {
      weight[c] = 0.25 * (1.0 + (J1 * corner_xi[c] + J2 * corner_eta[c]) / (3.0 * J0));
      const Vec2& next = x[(c + 1) % 4];
      const Vec2& previous = x[(c + 3) % 4];
      gradient_x[c] = inv * (next.y() - previous.y());
      gradient_y[c] = inv * -(next.x() - previous.x());
    }
  }

  // The corner factors of G_gp = sum_c S_g(x_c) g_c (above, with the r-z
  // weights), for the corners in the order of corner_xi, corner_eta.
  // Scalars, x and y apart (evaluate, below, says why).
  void corner_gradients(std::size_t p, const Mat2& s, double* gx, double* gy) const {
    if constexpr (Corners) {
      double w[4];
      quadrilateral_factors(p, s, w, gx, gy);
      return;
    }
    // s^-T = [[s11, -s10], [-s01, s00]] / det s.
    const double inv_det = gradient_scale / determinant(s);
    const double s10 = shear_sign * s(1, 0), s01 = shear_sign * s(0, 1);
    double weight_a = 0.0, weight_b = 0.0;
    if constexpr (G == Geometry::axisymmetric) {
      const double weight_r = 1.0 / (3.0 * position[p].x());
      weight_a = s(0, 0) * weight_r;
      weight_b = s(0, 1) * weight_r;
    }
    for (int c = 0; c < 4; ++c) {
      const double xi = corner_xi[c], eta = corner_eta[c];
      double gxi = 0.25 * xi, geta = 0.25 * eta;
      if constexpr (G == Geometry::axisymmetric) {
        gxi *= 1.0 + weight_b * eta;
        geta *= 1.0 + weight_a * xi;
      }
      gx[c] = inv_det * (s(1, 1) * gxi - s10 * geta);
      gy[c] = inv_det * (s(0, 0) * geta - s01 * gxi);
    }
  }

  // An upper bound of sum_g |G_gp| without the grid: the factors g_c sum to
  // zero, so G_gp = sum_c (S_g(x_c) - S_g(x_p)) g_c, and over the nodes
  // sum_g |S_g(a) - S_g(b)| is at most 2 (|a_x - b_x| + |a_y - b_y|) / h
  // (the bilinear hats, each a product of 1D hats of slope 1 / h) and at
  // most 2 (two partitions of unity). Any point serves as b: the domain's
  // centre (x_p, or a_0 for corner domains).
  double gradient_sum_bound(std::size_t p) const {
    const Mat2 s = domain(p);
    double gx[4], gy[4];
    corner_gradients(p, s, gx, gy);
    Vec2 centre = Vec2::Zero();
    if constexpr (Corners) centre = 0.25 * (corners[4 * p] + corners[4 * p + 1] + corners[4 * p + 2] + corners[4 * p + 3]);
    double bound = 0.0;
    for (int c = 0; c < 4; ++c) {
      Vec2 offset;
      if constexpr (Corners) offset = corners[4 * p + c] - centre;
      else offset = corner_xi[c] * s.col(0) + corner_eta[c] * s.col(1);
      bound += std::sqrt(gx[c] * gx[c] + gy[c] * gy[c]) * std::min(2.0, 2.0 * offset.cwiseAbs().sum() / grid->h);
    }
    return bound;
  }

  // A corner domain turned over, 4 det [a_1 a_2] <= 0 (monitors.hpp:
  // folded_domains). The factors above stay those of the signed integral over
  // the quadrilateral as it stands, finite while det [a_1 a_2] is not zero.
  bool folded(std::size_t p) const {
    if constexpr (Corners) return turned_over(corner_half_vectors(corners + 4 * p));
    return false;
  }

  // The centre lies between the walls (in r-z off the axis) and every corner
  // of the domain in the grid (ghost layers included).
  bool inside(std::size_t p) const {
    if constexpr (G == Geometry::axisymmetric)
      if (!(position[p].x() > 0.0)) return false;
    if (!inside_walls(*grid, position[p])) return false;
    if constexpr (Corners) {
      const Vec2* x = corners + 4 * p;
      const Vec2 low = x[0].cwiseMin(x[1]).cwiseMin(x[2].cwiseMin(x[3]));
      const Vec2 high = x[0].cwiseMax(x[1]).cwiseMax(x[2].cwiseMax(x[3]));
      return inside_cells(*grid, grid_coordinate(*grid, low)) && inside_cells(*grid, grid_coordinate(*grid, high));
    }
    // The corners x_p +- r_1 +- r_2 reach |r_1| + |r_2| along each axis: their
    // bounding box, without forming the four corners (the scan runs every step).
    const Vec2 reach = domain(p).cwiseAbs().rowwise().sum();
    return inside_cells(*grid, grid_coordinate(*grid, position[p] - reach)) &&
           inside_cells(*grid, grid_coordinate(*grid, position[p] + reach));
  }
};

}  // namespace mpmvv
