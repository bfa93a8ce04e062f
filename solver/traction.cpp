#include "traction.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "shape/linear.hpp"

namespace mpmvv {

namespace {

// Adds w f N_I(x) for the four nodes of the cell holding x.
void share_at(const GridGeometry& grid, const Vec2& x, double w, const Vec2& f, std::vector<NodeForce>& out) {
  int node[4];
  double weight[4];
  bilinear_cell_weights(grid, x, node, weight);
  for (int k = 0; k < 4; ++k)
    if (weight[k] != 0.0) out.push_back({node[k], (w * weight[k]) * f});
}

// The parameters s in (0, 1) where a -> b crosses the grid's lines, with 0 and 1.
void crossings(const GridGeometry& grid, const Vec2& a, const Vec2& b, std::vector<double>& s) {
  s.assign({0.0, 1.0});
  for (int axis = 0; axis < 2; ++axis) {
    const double from = (a[axis] - grid.origin[axis]) / grid.h, to = (b[axis] - grid.origin[axis]) / grid.h;
    if (from == to) continue;
    for (double line = std::ceil(std::min(from, to)); line < std::max(from, to); line += 1.0) {
      const double at = (line - from) / (to - from);
      if (at > 0.0 && at < 1.0) s.push_back(at);
    }
  }
  std::sort(s.begin(), s.end());
}

}  // namespace

void tractions_to_grid(const GridGeometry& grid, const Particles& P, const std::vector<BoundaryEdge>& edges,
                       const std::vector<Vec2>& force, TractionRule rule, bool reference_grid,
                       std::vector<NodeForce>& applied, GridFields& g) {
  applied.clear();
  std::vector<double> s;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const BoundaryEdge& edge = edges[e];
    const std::size_t p = edge.particle;
    const auto placed = [&](const Vec2& A) -> Vec2 {
      return reference_grid ? A : Vec2(P.position[p] + P.deformation_gradient[p] * (A - P.reference_position[p]));
    };
    const Vec2 a = placed(edge.A), b = placed(edge.B);
    if (!inside_cells(grid, grid_coordinate(grid, a)) || !inside_cells(grid, grid_coordinate(grid, b)))
      throw std::runtime_error(fmt::format(
          "the boundary side of the particle at X = ({:.6g}, {:.6g}) lies at ({:.6g}, {:.6g}) - ({:.6g}, {:.6g}), "
          "outside the grid [{:.6g}, {:.6g}] x [{:.6g}, {:.6g}]: its traction has no node to act on",
          P.reference_position[p].x(), P.reference_position[p].y(), a.x(), a.y(), b.x(), b.y(), grid.origin.x(),
          grid.upper().x(), grid.origin.y(), grid.upper().y()));
    const Vec2& f = force[e];
    if (rule == TractionRule::corners) {
      share_at(grid, a, 0.5, f, applied);
      share_at(grid, b, 0.5, f, applied);
      continue;
    }
    crossings(grid, a, b, s);
    for (std::size_t k = 0; k + 1 < s.size(); ++k) {
      const double s0 = s[k], s1 = s[k + 1], w = s1 - s0;
      if (w <= 0.0) continue;
      // Simpson's weights; each point's N_I is the grid's, whichever cell holds it.
      share_at(grid, a + s0 * (b - a), w / 6.0, f, applied);
      share_at(grid, a + 0.5 * (s0 + s1) * (b - a), 4.0 * w / 6.0, f, applied);
      share_at(grid, a + s1 * (b - a), w / 6.0, f, applied);
    }
  }
  for (const NodeForce& n : applied) g.force[std::size_t(n.node)] += n.force;
}

double traction_power(const std::vector<NodeForce>& applied, const GridFields& g) {
  double power = 0.0;
  for (const NodeForce& n : applied) power += n.force.dot(g.velocity[std::size_t(n.node)]);
  return power;
}

}  // namespace mpmvv
