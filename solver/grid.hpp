// The background grid: a uniform Cartesian mesh of square cells and the fields
// its nodes carry during one step (002_c3305cb8b1bc1490.txt section 1.5).
#pragma once

#include <cstddef>
#include <vector>

#include "tensor.hpp"

namespace mpmvv {

// Geometry only: where the nodes are. Node (i, j) sits at origin + h (i, j).
struct GridGeometry {
  Vec2 origin{0.0, 0.0};  // lower-left corner of the domain
  double h = 1.0;         // cell size, the same along both axes
  int cells_x = 1;
  int cells_y = 1;

  int nodes_x() const { return cells_x + 1; }
  int nodes_y() const { return cells_y + 1; }
  std::size_t node_count() const { return std::size_t(nodes_x()) * std::size_t(nodes_y()); }
  int node(int i, int j) const { return j * nodes_x() + i; }
  Vec2 node_position(int i, int j) const { return origin + h * Vec2(i, j); }
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
