// The background grid: a uniform Cartesian mesh of square cells and the fields
// its nodes carry during one step (002_c3305cb8b1bc1490.txt section 1.5).
#pragma once

#include <cstddef>
#include <vector>

#include "tensor.hpp"

namespace mpmvv {

// Geometry only: where the nodes are. Node (i, j) sits at origin + h (i, j).
// The walls are the node lines `ghost_layers` cells inside the grid's edges:
// a body may touch a wall, and particle domains that reach past it interpolate
// the ghost nodes beyond, which mirror the nodes inside (apply_walls).
struct GridGeometry {
  Vec2 origin{0.0, 0.0};  // lower-left corner of the grid, ghost layers included
  double h = 1.0;         // cell size, the same along both axes
  int cells_x = 1;        // ghost layers included
  int cells_y = 1;
  int ghost_layers = 0;   // cells beyond each wall

  // A grid whose walls enclose [lower, lower + h (walled_cells_x, walled_cells_y)]
  // with `ghost` cells beyond each wall.
  static GridGeometry walled(const Vec2& lower, double h, int walled_cells_x, int walled_cells_y, int ghost = 1) {
    return {lower - Vec2(ghost * h, ghost * h), h, walled_cells_x + 2 * ghost, walled_cells_y + 2 * ghost, ghost};
  }
  Vec2 wall_lower() const { return origin + h * Vec2(ghost_layers, ghost_layers); }
  Vec2 wall_upper() const { return origin + h * Vec2(cells_x - ghost_layers, cells_y - ghost_layers); }

  int nodes_x() const { return cells_x + 1; }
  int nodes_y() const { return cells_y + 1; }
  std::size_t node_count() const { return std::size_t(nodes_x()) * std::size_t(nodes_y()); }
  int node(int i, int j) const { return j * nodes_x() + i; }
  Vec2 node_position(int i, int j) const { return origin + h * Vec2(i, j); }
  Vec2 node_position(std::size_t node) const {
    const int row = int(node / std::size_t(nodes_x()));
    return node_position(int(node) - row * nodes_x(), row);
  }
  Vec2 upper() const { return origin + h * Vec2(cells_x, cells_y); }
};

// Node fields, one flat array per field.
struct GridFields {
  std::vector<double> mass;          // m_g, eq. 1.69
  std::vector<Vec2> momentum;        // m_g v_g, eq. 1.69
  std::vector<Vec2> force;           // f_ext - f_int + f_body, eqs. 1.69-1.70
  std::vector<Vec2> velocity;        // v_g^L, the time-advanced velocity, eq. 1.72
  std::vector<Vec2> acceleration;    // a_g, eq. 1.71

  void resize(std::size_t n) {
    mass.assign(n, 0.0);
    momentum.assign(n, Vec2::Zero());
    force.assign(n, Vec2::Zero());
    velocity.assign(n, Vec2::Zero());
    acceleration.assign(n, Vec2::Zero());
  }
};

}  // namespace mpmvv
