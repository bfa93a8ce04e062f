// uGIMP: a top-hat particle of fixed half-size l_p (eq. 1.90) convolved with
// the linear hat, eqs. 1.91-1.92 in each direction and their tensor product in
// 2D (002_c3305cb8b1bc1490.txt sections 1.6.2-1.6.3). The size is not convected
// with F ("UGIMP"); eq. 1.91 holds for l_p <= h/2, which one or more particles
// per cell per direction guarantees.
//
// In r-z the averages over the particle carry the weight r (eq. 1.85 with
// r dA): along r,
//   S_r = int S r' dr' / (2 l r_p),  G_r = int S' r' dr' / (2 l r_p),
//   <S / r>_r = int S dr' / (2 l r_p),
// in closed form below; along z the plain eqs. 1.91-1.92.
#pragma once

#include <algorithm>
#include <cstddef>

#include "../particles.hpp"
#include "gimp_lanes.hpp"
#include "linear.hpp"
#include "stencil.hpp"

namespace mpmvv {

// Effective 1D weight (eq. 1.91) and its derivative (eq. 1.92) for a node at
// signed distance d = x_p - x_g, cell size h, particle half-size l <= h/2.
struct GimpWeight1D {
  double weight;
  double derivative;
};

inline GimpWeight1D gimp_weight_1d(double d, double h, double l) {
  if (d <= -h - l || d > h + l) return {0.0, 0.0};
  if (d <= -h + l) {
    const double s = h + l + d;
    return {s * s / (4.0 * h * l), s / (2.0 * h * l)};
  }
  if (d <= -l) return {1.0 + d / h, 1.0 / h};
  if (d <= l) return {1.0 - (d * d + l * l) / (2.0 * h * l), -d / (h * l)};
  if (d <= h - l) return {1.0 - d / h, -1.0 / h};
  const double s = h + l - d;
  return {s * s / (4.0 * h * l), -s / (2.0 * h * l)};
}

// The hat S(u) = max(0, 1 - |u| / h) and its first moment
// M(u) = int_{-h}^{u} S(s) s ds (zero outside [-h, h]).
inline double hat(double u, double h) { return std::max(0.0, 1.0 - std::abs(u) / h); }
inline double hat_first_moment(double u, double h) {
  if (u <= -h || u >= h) return 0.0;
  const double cubic = u * u * u / (3.0 * h);
  return 0.5 * u * u + (u <= 0.0 ? cubic : -cubic) - h * h / 6.0;
}

// The r-weighted 1D factors of a node at x_g for a particle at r with half-size l.
struct GimpRadial1D {
  double weight;      // int S r' dr' / (2 l r)
  double derivative;  // int S' r' dr' / (2 l r)
  double hoop;        // int S dr' / (2 l r)
};

inline GimpRadial1D gimp_radial_1d(double r, double x_g, double h, double l) {
  const double d = r - x_g;
  const GimpWeight1D plain = gimp_weight_1d(d, h, l);
  // int S(u) (x_g + u) du over u in [d - l, d + l].
  const double moment = hat_first_moment(d + l, h) - hat_first_moment(d - l, h);
  const double inv_r = 1.0 / r;
  return {(x_g * plain.weight + moment / (2.0 * l)) * inv_r,
          // Integration by parts: [S r']_{r-l}^{r+l} - int S dr'.
          (hat(d + l, h) * (r + l) - hat(d - l, h) * (r - l)) / (2.0 * l) * inv_r - plain.weight * inv_r,
          plain.weight * inv_r};
}

template <Geometry G>
struct GimpShapeT {
  static constexpr int stencil_size = 9;
  static constexpr const char* name = "gimp";
  static constexpr Geometry geometry = G;
  static constexpr bool reads_deformation_gradient = false;
  static constexpr bool gradients_beyond_grid_basis = false;  // averages of the grid basis
  static constexpr bool has_domain = true;
  using GridBasis = LinearShapeT<G>;  // the domain averages the hats

  const GridGeometry* grid;
  const Vec2* position;
  const Vec2* half_size;
  double gradient_scale = 1.0;  // 1, but for a deliberate fault (faults.hpp: gimp-gradient)

  static GimpShapeT bind(const GridGeometry& grid, const Particles& particles, const Mat2* = nullptr,
                       double gradient_scale = 1.0) {
    return {&grid, particles.position.data(), particles.half_size.data(), gradient_scale};
  }

  // With l_p <= h/2 a particle reaches the node nearest to it and one on each
  // side, three per direction. A node beyond the grid carries zero weight when
  // the particle's domain lies inside the grid (inside()); it is skipped with a
  // zero weight on a node that exists.
  void evaluate(std::size_t p, Stencil<stencil_size>& s) const {
    const GridGeometry& g = *grid;
    const Vec2 x = position[p];
    const Vec2 xi = grid_coordinate(g, x);
    const int i0 = static_cast<int>(std::floor(xi.x() + 0.5)) - 1;
    const int j0 = static_cast<int>(std::floor(xi.y() + 0.5)) - 1;
    double wx[3], dx[3], hx[3], wy[3], dy[3];
    int ix[3], iy[3];
    for (int a = 0; a < 3; ++a) {
      const int i = i0 + a, j = j0 + a;
      const bool in_x = i >= 0 && i <= g.cells_x, in_y = j >= 0 && j <= g.cells_y;
      ix[a] = std::clamp(i, 0, g.cells_x);
      iy[a] = std::clamp(j, 0, g.cells_y);
      const double node_x = g.origin.x() + i * g.h;
      if constexpr (G == Geometry::axisymmetric) {
        const GimpRadial1D r = gimp_radial_1d(x.x(), node_x, g.h, half_size[p].x());
        wx[a] = in_x ? r.weight : 0.0;
        dx[a] = in_x ? gradient_scale * r.derivative : 0.0;
        hx[a] = in_x ? r.hoop : 0.0;
      } else {
        const GimpWeight1D w = gimp_weight_1d(x.x() - node_x, g.h, half_size[p].x());
        wx[a] = in_x ? w.weight : 0.0;
        dx[a] = in_x ? gradient_scale * w.derivative : 0.0;
      }
      const GimpWeight1D w = gimp_weight_1d((xi.y() - j) * g.h, g.h, half_size[p].y());
      wy[a] = in_y ? w.weight : 0.0;
      dy[a] = in_y ? gradient_scale * w.derivative : 0.0;
    }
    int k = 0;
    for (int b = 0; b < 3; ++b) {
      for (int a = 0; a < 3; ++a, ++k) {
        s.node[k] = g.node(ix[a], iy[b]);
        s.weight[k] = wx[a] * wy[b];
        s.gradient[k] = Vec2(dx[a] * wy[b], wx[a] * dy[b]);
        if constexpr (G == Geometry::axisymmetric) s.hoop[k] = hx[a] * wy[b];
      }
    }
  }

  // Plane strain evaluates eight particles at a time by the lane kernel
  // (gimp_lanes.hpp), to the same bits as evaluate.
  static constexpr bool lanes = G == Geometry::plane_strain;
  // Every lane's nodes are a 3 x 3 block but at the grid's edge (a domain is
  // at most a cell wide): particle-to-grid adds them by rows (stages.hpp:
  // scatter_by_rows).
  static constexpr bool lane_blocks_only = lanes;

  // Eight particles' stencils in two steps, as for CPDI (cpdi.hpp:
  // compute_lanes). The gradient bound is CPDI's, which averages of the grid
  // basis do not need: -1.
  using LaneBatch = LaneBatchOfStencils<GimpLaneStencils>;

  void compute_lanes(std::size_t first, int count, LaneBatch& batch, bool /*for_scan*/ = true,
                     const LaneBuild* build = nullptr) const
    requires lanes
  {
    const GridGeometry& g = *grid;
    GimpLaneInput in{values_of(position + first), values_of(half_size + first)};
    GimpLaneCopy copy;
    if (count < kLanes) {
      for (int l = 0; l < kLanes; ++l) {
        const std::size_t p = copied_lane_particle(first, count, l);
        std::copy_n(values_of(position + p), 2, copy.position + 2 * l);
        std::copy_n(values_of(half_size + p), 2, copy.half_size + 2 * l);
      }
      in = {copy.position, copy.half_size};
    }
    batch.first = first;
    const Vec2 wall_lower = g.wall_lower(), wall_upper = g.wall_upper(), upper = g.upper();
    const GimpLaneGrid lane_grid{g.origin.x(),   g.origin.y(),   g.h,            g.cells_x,
                                 g.cells_y,      g.nodes_x(),    wall_lower.x(), wall_lower.y(),
                                 wall_upper.x(), wall_upper.y(), upper.x(),      upper.y(),
                                 gradient_scale};
    if (build) gimp_lane_stencils(*build, lane_grid, in, batch.out);
    else gimp_lane_stencils(lane_grid, in, batch.out);
  }

  bool lane_inside(const LaneBatch& batch, int l) const
    requires lanes
  {
    return batch.out.inside[l] != 0;
  }

  // Lane l's entries as evaluate lists them, each passed to f(node, S_gp,
  // G_gp) in turn (as for CPDI, cpdi.hpp: for_each_lane_entry).
  template <class F>
  void for_each_lane_entry(const LaneBatch& batch, int l, F&& f) const
    requires lanes
  {
    const GridGeometry& g = *grid;
    const GimpLaneStencils& out = batch.out;
    for (int b = 0; b < 3; ++b)
      for (int a = 0; a < 3; ++a) {
        const int slot = a + 3 * b;
        f(g.node(out.node_i[a][l], out.node_j[b][l]), out.weight[slot][l],
          Vec2(out.gradient_x[slot][l], out.gradient_y[slot][l]));
      }
  }

  // Where lane l's nodes are a 3 x 3 block (scatter_lanes.hpp), its first
  // node; -1 where the kernel held a node at the grid's edge (its weight 0).
  std::ptrdiff_t lane_block_first(const LaneBatch& batch, int l) const
    requires lanes
  {
    return batch.out.block_first[l];
  }

  // No bounds of sum_g |G_gp|: uGIMP's gradients are the grid basis's.
  const double* lane_gradient_bounds(const LaneBatch&) const
    requires lanes
  {
    return nullptr;
  }

  // The particle's centre lies between the walls and its domain inside the
  // grid (ghost layers included).
  // The domain's half-vectors as columns: the undeformed square (uGIMP).
  Mat2 domain(std::size_t p) const {
    Mat2 s = Mat2::Zero();
    s(0, 0) = half_size[p].x();
    s(1, 1) = half_size[p].y();
    return s;
  }

  bool inside(std::size_t p) const {
    const Vec2 lo = position[p] - half_size[p], hi = position[p] + half_size[p];
    const Vec2 top = grid->upper();
    return inside_walls(*grid, position[p]) && lo.x() >= grid->origin.x() && lo.y() >= grid->origin.y() &&
           hi.x() <= top.x() && hi.y() <= top.y();
  }
};

using GimpShape = GimpShapeT<Geometry::plane_strain>;

}  // namespace mpmvv
