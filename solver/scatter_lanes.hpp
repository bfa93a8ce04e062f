// Particle-to-grid's sums (stages.hpp: particles_to_grid, eqs. 1.69-1.70 of
// 002_c3305cb8b1bc1490.txt) for a batch of particles whose stencils a lane
// kernel left as 3 x 3 blocks of nodes (shape/cpdi_lanes.hpp,
// shape/gimp_lanes.hpp), or 2 x 2 (shape/linear_lanes.hpp, in the same
// layout): slot a + 3 b at node first + a + b row. A CPDI domain stretched
// past a cell lists four entries per corner (kByCorners, lanes.hpp): a
// 2 x 2 block at each corner's cell, added corner by corner as the scalar
// map adds its entries, so that a node its corners share takes their terms
// one at a time in the same order.
//
// Why: the nodes of a block's row lie side by side in each of the thread's
// sum arrays, so a particle adds to a row's three nodes with one vector per
// field (four lanes, the fourth adding zero to the node after), where the
// scalar map adds to nine nodes one value at a time (callgrind: 328
// instructions a CPDI particle-step). Each lane of a row forms the scalar
// map's value by the same operations in the same order, and the particles
// add in the order the scalar map takes them, so the sums are the same to
// the bit. A slot outside the particle's stencil (CPDI lists two columns
// or rows where its corners share a cell) holds weight and gradient 0 and
// adds +-0, which leaves every sum as it is: a sum from +0 never becomes -0.
#pragma once

#include <cstddef>

#include "lanes.hpp"

namespace mpmvv {

// One thread's sums, one array per field, nodes in the grid's order, each
// with room past its last node for a block's row beyond it (ScatterBuffers).
struct ScatterRows {
  double* mass;
  double* momentum_x;
  double* momentum_y;
  double* force_x;
  double* force_y;
  std::ptrdiff_t row;  // nodes along x
};

// The fields a batch adds, as particles_to_grid's `Fields` selects them.
struct ScatterFields {
  bool mass, momentum, internal_force, body_force;
};

// The particles, read in place (Particles' arrays; tensor.hpp: values_of):
// m_p, v_p, V_p, sigma_p (column by column) and b_p; an array a stage does
// not add may be null.
struct ScatterParticles {
  const double* mass;
  const double* velocity;     // 2 a particle
  const double* volume;
  const double* stress;       // 4 a particle
  const double* body_force;   // 2 a particle
};

// The batch: particle first + l is added where bit l of `pending` is set,
// at the block from node first_node[l], with its stencil's slots in
// weight[slot][l], gradient_x[slot][l], gradient_y[slot][l]; where
// first_node[l] is kByCorners, at corner c's block from corner_first[c][l]
// with slots 4 c + a + 2 b of the corner_* arrays.
struct ScatterLaneBatch {
  const double (*weight)[kLanes];
  const double (*gradient_x)[kLanes];
  const double (*gradient_y)[kLanes];
  int block = 3;  // nodes along a block's side: 3 (CPDI, uGIMP) or 2 (linear: slots 0, 1, 3, 4)
  const double (*corner_weight)[kLanes] = nullptr;  // CPDI's wide entries (cpdi_lanes.hpp)
  const double (*corner_gradient_x)[kLanes] = nullptr;
  const double (*corner_gradient_y)[kLanes] = nullptr;
  const int (*corner_first)[kLanes] = nullptr;
  std::size_t first = 0;
  unsigned pending = 0;
  std::ptrdiff_t first_node[kLanes];
};

// Adds the pending lanes' particles, in lane order, each with the factors
// particles_to_grid forms (m_p, m_p v_p, V_p sigma_p, m_p b_p), and clears
// `pending`.
void scatter_lanes(const ScatterFields& fields, const ScatterParticles& P, ScatterLaneBatch& batch,
                   const ScatterRows& out);
// With a given build, which the CPU must have (cpu_has).
void scatter_lanes(LaneBuild build, const ScatterFields& fields, const ScatterParticles& P, ScatterLaneBatch& batch,
                   const ScatterRows& out);

// Each build's own, compiled for its instructions (solver/CMakeLists.txt).
MPMVV_LANE_KERNEL(void scatter_lanes(const ScatterFields& fields, const ScatterParticles& P,
                                     const ScatterLaneBatch& batch, const ScatterRows& out))

}  // namespace mpmvv
