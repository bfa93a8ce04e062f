// The current domain of every particle as a polygon, for a monitor of how the
// domains cover the body (tools/app/scene/coverage.hpp: the partition of
// unity of the particle basis, whose holes 003_0440bbfcfbc3a876.txt shows
// opening under extreme 2D deformation and letting material interpenetrate).
// The polygon is the one the method integrates over: the parallelogram
// x_p +- r_1 +- r_2 of convected and turned CPDI (eq. 1.97) and of uGIMP's
// fixed square, the quadrilateral of CPDI's corner domains, exact CPDI's own
// outline (cpdi_outline.hpp). Linear and B-spline MPM have no domain, and the
// total Lagrangian formulation weighs the reference domains for the whole run
// (total_lagrangian.hpp), which cover the body as they did at the start: for
// those the list is empty.
#pragma once

#include <cstddef>
#include <vector>

#include "particles.hpp"
#include "shape/lane_shared.hpp"  // kCornerXi, kCornerEta
#include "shape/stencil.hpp"

namespace mpmvv {

// Particle p's vertices are vertex[first[p]] .. vertex[first[p + 1] - 1], in
// the order the method walks its outline [m]; `first` has one entry more than
// there are particles, and both are empty for a method without domains.
struct DomainPolygons {
  std::vector<Vec2> vertex;
  std::vector<std::size_t> first;
  std::size_t size() const { return first.empty() ? 0 : first.size() - 1; }
};

template <class Shape>
DomainPolygons domain_polygons(const Shape& shape, const Particles& P, const GridGeometry& grid) {
  DomainPolygons d;
  if constexpr (Shape::has_domain && !requires { Shape::total_lagrangian; }) {
    const std::size_t n = P.size();
    d.first.reserve(n + 1);
    d.vertex.reserve(4 * n);
    for (std::size_t p = 0; p < n; ++p) {
      d.first.push_back(d.vertex.size());
      if constexpr (requires(Vec2* c) { shape.outline(p, c); }) {
        Vec2 c[Shape::kClipBuffer];
        const int count = shape.outline(p, c);  // grid coordinates
        for (int k = 0; k < count; ++k) d.vertex.push_back(grid.origin + grid.h * c[k]);
      } else {
        const Mat2 s = shape.domain(p);
        for (int c = 0; c < 4; ++c) {
          if constexpr (requires { shape.corner(p, s, c); })
            d.vertex.push_back(shape.corner(p, s, c));
          else
            d.vertex.push_back(P.position[p] + kCornerXi[c] * s.col(0) + kCornerEta[c] * s.col(1));
        }
      }
    }
    d.first.push_back(d.vertex.size());
  }
  return d;
}

}  // namespace mpmvv
