// The grid update: nodal velocities from momentum, the forces of a step, and
// the symmetry walls. A stage of solver/stages.hpp.
#pragma once

#include "particle_to_grid.hpp"

namespace mpmvv {

// ---------------------------------------------------------------- grid update

// a_g = f_g / m_g (eq. 1.71) and v_g^L = v_g + a_g dt_kick (eq. 1.72). The
// kick is the step itself, or under central differences the mean of the steps
// on either side of t_n. Nodes no particle reaches carry no mass and stay at
// rest, and so do nodes whose mass is at most `unresolved`, the mass below
// which the shape's weights are round-off (grid_conditions.hpp:
// unresolved_node_mass), where f_g / m_g would divide the round-off of a
// force balance by the round-off of a mass.
inline void update_grid_motion(GridFields& g, double kick, double unresolved = 0.0) {
  const std::size_t nodes = g.mass.size();
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < nodes; ++i) {
    if (g.mass[i] > unresolved) {
      const double inv_m = 1.0 / g.mass[i];
      g.acceleration[i] = g.force[i] * inv_m;
      g.velocity[i] = g.momentum[i] * inv_m + g.acceleration[i] * kick;
    } else {
      g.acceleration[i].setZero();
      g.velocity[i].setZero();
    }
  }
}

// v_g = (m_g v_g) / m_g without advancing it: the velocity a USF step takes its
// gradient from, and the remapped velocity of MUSL.
inline void grid_velocity_from_momentum(GridFields& g) {
  const std::size_t nodes = g.mass.size();
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < nodes; ++i)
    g.velocity[i] = g.mass[i] > 0.0 ? Vec2(g.momentum[i] / g.mass[i]) : Vec2::Zero();
}

// Symmetry (roller) walls on the four sides: nodes on a wall keep no velocity
// and no acceleration normal to it, tangential motion is free. A ghost node k
// cells beyond a wall takes the mirror image of the node k cells inside: the
// tangential components equal, the normal component negated. In r-z the wall
// r = 0 is the axis and the same mirror is the axisymmetry condition. The
// x-walls are mirrored first over all rows, then the y-walls over all columns,
// so corner ghosts mirror in both. `swapped` is a deliberate fault
// (faults.hpp: swapped-walls): each wall treats the tangential component as
// its normal one; `mirrored` another (mirrored-wall): a wall node's normal
// components are reflected, -v_n, instead of set to zero.
inline void apply_walls(const GridGeometry& grid, GridFields& g, bool swapped = false, bool mirrored = false) {
  const int nx = grid.nodes_x(), ny = grid.nodes_y(), ghost = grid.ghost_layers;
  const int x_walls[2] = {ghost, nx - 1 - ghost}, y_walls[2] = {ghost, ny - 1 - ghost};
  const int x_normal = swapped ? 1 : 0, y_normal = 1 - x_normal;
  // A wall node's normal velocity and acceleration: zero, or under
  // mirrored-wall reflected.
  auto on_wall = [&g, mirrored](int node, int normal) {
    if (mirrored) {
      g.velocity[node][normal] = -g.velocity[node][normal];
      g.acceleration[node][normal] = -g.acceleration[node][normal];
    } else {
      g.velocity[node][normal] = 0.0;
      g.acceleration[node][normal] = 0.0;
    }
  };
  auto mirror = [&g](int from, int to, int normal) {
    g.velocity[to] = g.velocity[from];
    g.acceleration[to] = g.acceleration[from];
    g.velocity[to][normal] = -g.velocity[from][normal];
    g.acceleration[to][normal] = -g.acceleration[from][normal];
  };
  for (int j = 0; j < ny; ++j) {
    for (int w : x_walls) on_wall(grid.node(w, j), x_normal);
    for (int k = 1; k <= ghost; ++k) {
      mirror(grid.node(x_walls[0] + k, j), grid.node(x_walls[0] - k, j), x_normal);
      mirror(grid.node(x_walls[1] - k, j), grid.node(x_walls[1] + k, j), x_normal);
    }
  }
  for (int i = 0; i < nx; ++i) {
    for (int w : y_walls) on_wall(grid.node(i, w), y_normal);
    for (int k = 1; k <= ghost; ++k) {
      mirror(grid.node(i, y_walls[0] + k), grid.node(i, y_walls[0] - k), y_normal);
      mirror(grid.node(i, y_walls[1] - k), grid.node(i, y_walls[1] + k), y_normal);
    }
  }
}

}  // namespace mpmvv
