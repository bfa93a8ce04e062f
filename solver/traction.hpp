// Tractions on the body's boundary (SceneStages::traction): the scene names
// the sides of its particles' domains that lie on the boundary and the
// nominal force on each, the integral of P N over the side in the reference
// configuration (a dead load: 002_c3305cb8b1bc1490.txt eq. 1.70's f_ext with
// t dA = P N dA); the solver shares each side's force among the grid nodes
// at the side's current position and adds it to the nodes' force.
//
// How a side's force is shared follows how the method forms the internal
// force, so that a homogeneous stress, which carries the same traction on the
// boundary, is balanced node by node to round-off (the patch test):
// - CPDI (corner interpolation, eq. 1.99) forms grad S_Ip from the boundary
//   integral of N_I interpolated linearly between the domain's corners along
//   each side, so a side's share at node I is the mean of N_I at its two ends;
// - the other methods average the grid's bilinear N_I over the domain, whose
//   boundary integral is that of N_I itself: the share is the integral of N_I
//   along the side, cell by cell, each piece by Simpson's rule (exact: along a
//   line N_I is quadratic within a cell).
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "grid.hpp"
#include "particles.hpp"
#include "tensor.hpp"

namespace mpmvv {

// One side of particle `particle`'s domain on the body's boundary, its ends
// in the reference configuration.
struct BoundaryEdge {
  std::size_t particle;
  Vec2 A, B;
};

class BoundaryTraction {
 public:
  explicit BoundaryTraction(std::vector<BoundaryEdge> edges) : edges_(std::move(edges)) {}
  virtual ~BoundaryTraction() = default;
  const std::vector<BoundaryEdge>& edges() const { return edges_; }
  // The nominal force on each side at time t, the integral of P(X, t) N over
  // its reference span [N per unit depth]; force has one entry per side.
  virtual void evaluate(double t, std::vector<Vec2>& force) const = 0;

 private:
  std::vector<BoundaryEdge> edges_;
};

enum class TractionRule { corners, exact };

// A node's share of the tractions, kept for the work they do.
struct NodeForce {
  int node;
  Vec2 force;
};

// Each side's force shared among the nodes at the side's current ends a, b:
// x_p + F_p (A - X_p) in the updated formulation (the material line the
// domain's side maps to; computed as the shapes compute the domain's
// corners, traction.cpp), A itself in the total one (its grid is the
// reference configuration). Adds to g.force; `applied` holds each share.
// Throws std::runtime_error naming the side when an end has left the grid.
void tractions_to_grid(const GridGeometry& grid, const Particles& P, const std::vector<BoundaryEdge>& edges,
                       const std::vector<Vec2>& force, TractionRule rule, bool reference_grid,
                       std::vector<NodeForce>& applied, GridFields& g);

// The tractions' power on the grid's updated velocity, sum f_I . v_I^L.
double traction_power(const std::vector<NodeForce>& applied, const GridFields& g);

}  // namespace mpmvv
