// Tracers: material points moved with the grid velocity, where probes read the
// motion. A stage of solver/stages.hpp.
#pragma once

#include "stress_update.hpp"

namespace mpmvv {

// ---------------------------------------------------------------- tracers

// Massless probe points move with the grid velocity, interpolated with the
// bilinear hat and weighted by nodal mass, v = sum S m v / sum S m: they sample
// the motion the method computes without changing it, and at a free surface
// the nodes beyond the body, which carry only a sliver of mass and whatever
// velocity that sliver gives them, do not drag a tracer on the surface along.
// A tracer that leaves the grid, or finds no mass around it, becomes NaN.
//
// Under the total Lagrangian formulation the grid is the reference
// configuration: `reference` then holds each tracer's reference position,
// where the grid is read, while `tracers` holds where it is now.
inline void advect_tracers(const GridGeometry& grid, const GridFields& g, std::vector<Vec2>& tracers,
                           double dt, const std::vector<Vec2>* reference = nullptr) {
  for (std::size_t t = 0; t < tracers.size(); ++t) {
    Vec2& x = tracers[t];
    const Vec2& at = reference ? (*reference)[t] : x;
    if (!inside_cells(grid, grid_coordinate(grid, at)) || !x.allFinite()) {
      x.setConstant(std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    int node[4];
    double w[4];
    bilinear_cell_weights(grid, at, node, w);
    Vec2 momentum = Vec2::Zero();
    double mass = 0.0;
    for (int k = 0; k < 4; ++k) {
      momentum += w[k] * g.mass[node[k]] * g.velocity[node[k]];
      mass += w[k] * g.mass[node[k]];
    }
    if (mass > 0.0) {
      x += dt * momentum / mass;
    } else {
      x.setConstant(std::numeric_limits<double>::quiet_NaN());
    }
  }
}

}  // namespace mpmvv
