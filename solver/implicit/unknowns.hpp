// The unknowns of the implicit static step (static_stepper.hpp): the free
// components of the nodes the particles reach, between the walls. A wall
// fixes its normal component, a node constraint the component it prescribes,
// a rigid master the normal component of a node in contact; ghost nodes
// mirror the nodes inside. Each node's displacement is
//   u = base + sum_k q[dof_k] direction_k.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "solver/boundary.hpp"
#include "solver/contact.hpp"
#include "solver/grid.hpp"
#include "solver/tensor.hpp"

namespace mpmvv {

// The node line of the lower (k = 0) or upper (k = 1) wall across x, or across y.
inline int wall_node_x(const GridGeometry& grid, int k) {
  return k == 0 ? grid.ghost_layers : grid.nodes_x() - 1 - grid.ghost_layers;
}
inline int wall_node_y(const GridGeometry& grid, int k) {
  return k == 0 ? grid.ghost_layers : grid.nodes_y() - 1 - grid.ghost_layers;
}

// How a node's displacement depends on the unknowns.
struct NodeMap {
  int dof[2] = {-1, -1};
  Vec2 direction[2] = {Vec2::Zero(), Vec2::Zero()};
  Vec2 base = Vec2::Zero();
};

// A rigid master's say in the unknowns: the nodes in contact (active), each
// node's gap to it, and its motion over the step. master = nullptr: no master.
struct ContactUnknowns {
  const RigidBody* master;
  const std::vector<unsigned char>& active;
  const std::vector<double>& gap;
  Vec2 master_step;
};

class GridUnknowns {
 public:
  // Numbers the free components of the nodes with mass for the step from t
  // to t + dt, with the constraints' increments over it as the fixed values.
  void build(const GridGeometry& grid, const std::vector<double>& node_mass,
             const std::vector<NodeConstraint>& constraints, const ContactUnknowns& contact, double t, double dt) {
    const int nx = grid.nodes_x(), ny = grid.nodes_y();
    map_.assign(grid.node_count(), NodeMap{});
    std::vector<unsigned char> fixed(2 * grid.node_count(), 0);
    std::vector<double> value(2 * grid.node_count(), 0.0);
    for (int j = 0; j < ny; ++j)
      for (int w = 0; w < 2; ++w) fixed[2 * std::size_t(grid.node(wall_node_x(grid, w), j))] = 1;
    for (int i = 0; i < nx; ++i)
      for (int w = 0; w < 2; ++w) fixed[2 * std::size_t(grid.node(i, wall_node_y(grid, w))) + 1] = 1;
    for (const NodeConstraint& c : constraints) {
      const double increment = c.displacement(t + dt) - c.displacement(t);
      for (std::size_t node : c.nodes) {
        fixed[2 * node + std::size_t(c.axis)] = 1;
        value[2 * node + std::size_t(c.axis)] = increment;
      }
    }
    count_ = 0;
    for (int j = wall_node_y(grid, 0); j <= wall_node_y(grid, 1); ++j)
      for (int i = wall_node_x(grid, 0); i <= wall_node_x(grid, 1); ++i) {
        const std::size_t node = std::size_t(grid.node(i, j));
        if (!(node_mass[node] > 0.0)) continue;
        NodeMap& m = map_[node];
        for (int a = 0; a < 2; ++a) m.base[a] = value[2 * node + std::size_t(a)];
        if (contact.master && contact.active[node]) {
          // u.n = dU.n - gap: the normal part fixed, the rest free.
          const Vec2 n = contact.master->normal(grid.node_position(i, j), t);
          const double c = contact.master_step.dot(n) - contact.gap[node];
          const bool fx = fixed[2 * node], fy = fixed[2 * node + 1];
          if (!fx && !fy) {
            m.base = c * n;
            m.dof[0] = count_++;
            m.direction[0] = Vec2(-n.y(), n.x());
          } else if (fx && !fy && std::abs(n.y()) > 1e-12) {
            m.base.y() = (c - m.base.x() * n.x()) / n.y();
          } else if (fy && !fx && std::abs(n.x()) > 1e-12) {
            m.base.x() = (c - m.base.y() * n.y()) / n.x();
          }
          continue;
        }
        int k = 0;
        for (int a = 0; a < 2; ++a)
          if (!fixed[2 * node + std::size_t(a)]) {
            m.dof[k] = count_++;
            m.direction[k] = a == 0 ? Vec2(1.0, 0.0) : Vec2(0.0, 1.0);
            ++k;
          }
      }
    mirror_ghost_nodes(grid);
  }

  int count() const { return count_; }
  std::size_t nodes() const { return map_.size(); }
  const NodeMap& node(std::size_t i) const { return map_[i]; }

  // The unknowns that come closest to the displacements u (zero at a step's
  // start; a contact pass starts from the pass before it).
  void closest(const std::vector<Vec2>& u, std::vector<double>& q) const {
    q.assign(std::size_t(count_), 0.0);
    for (std::size_t i = 0; i < map_.size(); ++i)
      for (int k = 0; k < 2; ++k)
        if (map_[i].dof[k] >= 0) q[std::size_t(map_[i].dof[k])] = (u[i] - map_[i].base).dot(map_[i].direction[k]);
  }

  // The node displacements of the unknowns q; with base = false, of the
  // correction q alone (its fixed parts zero).
  template <class Q>
  void displacements(const Q& q, std::vector<Vec2>& u, bool base = true) const {
    u.resize(map_.size());
    for (std::size_t i = 0; i < map_.size(); ++i) {
      const NodeMap& m = map_[i];
      Vec2 v = base ? m.base : Vec2::Zero();
      for (int k = 0; k < 2; ++k)
        if (m.dof[k] >= 0) v += q[std::size_t(m.dof[k])] * m.direction[k];
      u[i] = v;
    }
  }

  // r -= the node forces along each unknown's direction.
  void subtract_forces(const std::vector<Vec2>& force, std::vector<double>& r) const {
    for (std::size_t i = 0; i < map_.size(); ++i)
      for (int k = 0; k < 2; ++k)
        if (map_[i].dof[k] >= 0) r[std::size_t(map_[i].dof[k])] -= map_[i].direction[k].dot(force[i]);
  }

  // Each node's two unknowns (-1: none), as build numbered them.
  std::vector<int> numbering() const {
    std::vector<int> dofs;
    dofs.reserve(2 * map_.size());
    for (const NodeMap& m : map_) dofs.insert(dofs.end(), {m.dof[0], m.dof[1]});
    return dofs;
  }

 private:
  // Ghost nodes: the mirror image across the walls they lie beyond.
  void mirror_ghost_nodes(const GridGeometry& grid) {
    const int nx = grid.nodes_x(), ny = grid.nodes_y();
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        int mi = i, mj = j;
        Vec2 sign(1.0, 1.0);
        if (i < wall_node_x(grid, 0)) mi = 2 * wall_node_x(grid, 0) - i, sign.x() = -1.0;
        if (i > wall_node_x(grid, 1)) mi = 2 * wall_node_x(grid, 1) - i, sign.x() = -1.0;
        if (j < wall_node_y(grid, 0)) mj = 2 * wall_node_y(grid, 0) - j, sign.y() = -1.0;
        if (j > wall_node_y(grid, 1)) mj = 2 * wall_node_y(grid, 1) - j, sign.y() = -1.0;
        if (mi == i && mj == j) continue;
        if (mi < 0 || mi >= nx || mj < 0 || mj >= ny) continue;
        NodeMap m = map_[std::size_t(grid.node(mi, mj))];
        m.base = m.base.cwiseProduct(sign);
        for (int k = 0; k < 2; ++k) m.direction[k] = m.direction[k].cwiseProduct(sign);
        map_[std::size_t(grid.node(i, j))] = m;
      }
  }

  std::vector<NodeMap> map_;
  int count_ = 0;
};

}  // namespace mpmvv
