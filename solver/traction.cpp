#include "traction.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "shape/linear.hpp"

namespace mpmvv {

namespace {

// Adds w f N_I for the four nodes of the cell holding grid coordinate xi.
void share_at(const GridGeometry& grid, const Vec2& xi, double w, const Vec2& f, std::vector<NodeForce>& out) {
  int node[4];
  double weight[4];
  bilinear_cell_weights_at(grid, xi, node, weight);
  for (int k = 0; k < 4; ++k)
    if (weight[k] != 0.0) out.push_back({node[k], (w * weight[k]) * f});
}

// The parameters s in (0, 1) where a -> b (grid coordinates) crosses the
// grid's lines, with 0 and 1.
void crossings(const Vec2& a, const Vec2& b, std::vector<double>& s) {
  s.assign({0.0, 1.0});
  for (int axis = 0; axis < 2; ++axis) {
    const double from = a[axis], to = b[axis];
    if (from == to) continue;
    for (double line = std::ceil(std::min(from, to)); line < std::max(from, to); line += 1.0) {
      const double at = (line - from) / (to - from);
      if (at > 0.0 && at < 1.0) s.push_back(at);
    }
  }
  std::sort(s.begin(), s.end());
}

// The grid coordinate of the end A of a side of particle p's domain in the
// updated formulation, x_p + F_p (A - X_p), computed as the shapes compute
// the domain's corner there (cpdi_outline.hpp): from the outline's vertex at
// A when the particle has an outline of its own, else from its half sizes
// (x_p + or - F_p l_x e_x / h, then + or - F_p l_y e_y / h, in grid
// coordinates). A side that lies on a grid line to round-off then reaches
// the node across it by the same sliver as the domain does, and exact CPDI's
// volume integral and this line integral balance there to the round-off of
// the sliver's own size. (The reference ends A are the body's sides; the
// domains' corners are the seeding's, which round differently.)
Vec2 side_end(const GridGeometry& grid, const Particles& P, std::size_t p, const Vec2& A) {
  const Mat2& F = P.deformation_gradient[p];
  const Vec2 x = grid_coordinate(grid, P.position[p]);
  const Vec2 d = A - P.reference_position[p];
  if (!P.domain_first.empty() && P.domain_first[p + 1] > P.domain_first[p]) {
    const Vec2* vertex = P.domain_vertex.data() + P.domain_first[p];
    const int count = int(P.domain_first[p + 1] - P.domain_first[p]);
    int nearest = 0;
    for (int k = 1; k < count; ++k)
      if ((vertex[k] - d).squaredNorm() < (vertex[nearest] - d).squaredNorm()) nearest = k;
    if ((vertex[nearest] - d).norm() <= 1e-9 * d.norm()) {
      const Mat2 Fh = F / grid.h;
      return x + Fh * vertex[nearest];
    }
  } else if (!P.half_size.empty() && P.domain_corner.empty()) {
    Mat2 s = F;
    s.col(0) *= P.half_size[p].x();
    s.col(1) *= P.half_size[p].y();
    s = s / grid.h;
    Vec2 end = d.x() > 0.0 ? Vec2(x + s.col(0)) : Vec2(x - s.col(0));
    return d.y() > 0.0 ? Vec2(end + s.col(1)) : Vec2(end - s.col(1));
  }
  return grid_coordinate(grid, P.position[p] + F * d);
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
      return reference_grid ? grid_coordinate(grid, A) : side_end(grid, P, p, A);
    };
    const Vec2 a = placed(edge.A), b = placed(edge.B);
    if (!inside_cells(grid, a) || !inside_cells(grid, b)) {
      const Vec2 xa = grid.origin + grid.h * a, xb = grid.origin + grid.h * b;
      throw std::runtime_error(fmt::format(
          "the boundary side of the particle at X = ({:.6g}, {:.6g}) lies at ({:.6g}, {:.6g}) - ({:.6g}, {:.6g}), "
          "outside the grid [{:.6g}, {:.6g}] x [{:.6g}, {:.6g}]: its traction has no node to act on",
          P.reference_position[p].x(), P.reference_position[p].y(), xa.x(), xa.y(), xb.x(), xb.y(),
          grid.origin.x(), grid.upper().x(), grid.origin.y(), grid.upper().y()));
    }
    const Vec2& f = force[e];
    if (rule == TractionRule::corners) {
      share_at(grid, a, 0.5, f, applied);
      share_at(grid, b, 0.5, f, applied);
      continue;
    }
    crossings(a, b, s);
    // A piece's ends are the side's own ends where they are (bit for bit, as
    // side_end placed them), else the points where it crosses a grid line.
    const auto at = [&](double t) -> Vec2 { return t == 0.0 ? a : t == 1.0 ? b : Vec2(a + t * (b - a)); };
    for (std::size_t k = 0; k + 1 < s.size(); ++k) {
      const double s0 = s[k], s1 = s[k + 1], w = s1 - s0;
      if (w <= 0.0) continue;
      // Simpson's weights; each point's N_I is the grid's, whichever cell holds it.
      share_at(grid, at(s0), w / 6.0, f, applied);
      share_at(grid, a + 0.5 * (s0 + s1) * (b - a), 4.0 * w / 6.0, f, applied);
      share_at(grid, at(s1), w / 6.0, f, applied);
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
