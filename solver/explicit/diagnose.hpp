// Why a particle the scan flagged stops an explicit run (Stepper::diagnose):
// its state, its J, or where its support reaches.
#pragma once

#include <cmath>
#include <cstddef>

#include <fmt/format.h>

#include "../stages.hpp"
#include "../particles.hpp"
#include "../stepper.hpp"

namespace mpmvv {

template <class Shape>
ParticleFault diagnose_particle(const Shape& shape, const Particles& P, const GridGeometry& grid, std::size_t p) {
  const Vec2& x = P.position[p];
  if (!(x.allFinite() && P.velocity[p].allFinite() && P.deformation_gradient[p].allFinite() &&
        P.stress[p].allFinite()))
    return {"nan", fmt::format("non-finite state at x = ({:.6g}, {:.6g})", x.x(), x.y())};
  if constexpr (Shape::geometry == Geometry::axisymmetric)
    if (!std::isfinite(P.hoop_stress[p]))
      return {"nan", fmt::format("non-finite hoop stress at x = ({:.6g}, {:.6g})", x.x(), x.y())};
  const double J = determinant(P.deformation_gradient[p]) * out_of_plane_stretch<Shape::geometry>(P, p);
  if (!(J > 0.0)) return {"non-positive J", fmt::format("J = {:.6g} at x = ({:.6g}, {:.6g})", J, x.x(), x.y())};
  if (!shape.inside(p)) {
    if (!inside_walls(grid, x))
      return {"outside grid", fmt::format("the particle at ({:.6g}, {:.6g}) has crossed a wall", x.x(), x.y())};
    if constexpr (requires { shape.clear_of_walls(p); })
      if (!shape.clear_of_walls(p))
        return {"outside grid", fmt::format("the particle at ({:.6g}, {:.6g}) has come closer to a wall than its "
                                            "B-spline support allows (half a cell quadratic, a cell cubic: it "
                                            "would reach the mirrored ghost nodes)",
                                            x.x(), x.y())};
    if constexpr (requires { shape.within_stencil(p); })
      if (!shape.within_stencil(p))
        return {"domain too wide", fmt::format("the domain of the particle at ({:.6g}, {:.6g}) spans more cells "
                                               "than its stencil holds", x.x(), x.y())};
    return {"outside grid", fmt::format("support of the particle at ({:.6g}, {:.6g}) leaves the grid", x.x(), x.y())};
  }
  return {"", ""};
}

}  // namespace mpmvv
