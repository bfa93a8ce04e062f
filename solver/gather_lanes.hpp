// Grid-to-particle's sums (stages.hpp: grid_to_particles, eqs. 1.73 and 1.76
// of 002_c3305cb8b1bc1490.txt) for eight particles at once, each in a lane
// (lanes.hpp), whose stencils a lane kernel left as 3 x 3 or 2 x 2 blocks
// of nodes (scatter_lanes.hpp: slot a + 3 b at node first + a + b row):
//   a_p = sum_g S_gp a_g,  v_p^L = sum_g S_gp v_g^L,  L_p = sum_g v_g^L (x) G_gp.
//
// Why: the scalar update reads a node's a_g and v_g from two arrays and
// sums them two values at a time. Here a node's four values lie side by
// side (motion: a_x, a_y, v_x, v_y, node by node), one load a lane, and a
// transpose turns the lanes' loads into four vectors over the lanes, so
// that every product and sum runs on all the lanes at once (callgrind: 223
// instructions a CPDI particle-step for the scalar update). Each sum takes
// its products in the scalar update's order, slot by slot, so the sums are
// the same to the bit; a slot outside a lane's stencil holds weight and
// gradient 0 and adds +-0, which leaves a sum from +0 as it is (the motion
// array is finite, its rows past the last node 0).
#pragma once

#include <cstddef>

#include "lanes.hpp"

namespace mpmvv {

// The batch's stencils (S_gp and G_gp by slot and lane) and each lane's
// block, from its first node; a lane that does not go by rows names any
// node of the grid (its sums are not read). A lane at kByCorners (lanes.hpp:
// a CPDI domain stretched past a cell) sums its sixteen entries by itself,
// corner c's slots 4 c + a + 2 b of the corner_* arrays at node
// corner_first[c][l] + a + b row, in the scalar update's order.
struct GatherLaneBatch {
  const double (*weight)[kLanes];
  const double (*gradient_x)[kLanes];
  const double (*gradient_y)[kLanes];
  int block = 3;  // nodes along a block's side: 3 (CPDI, uGIMP) or 2 (linear: slots 0, 1, 3, 4)
  const double (*corner_weight)[kLanes] = nullptr;  // CPDI's wide entries (cpdi_lanes.hpp)
  const double (*corner_gradient_x)[kLanes] = nullptr;
  const double (*corner_gradient_y)[kLanes] = nullptr;
  const int (*corner_first)[kLanes] = nullptr;
  alignas(32) long long first_node[kLanes];
};

// The update the sums drive, where `particles` is given (plane strain, no
// affine field): the eight particles' x_p, v_p, F_p (column by column) and
// V_p0, each array holding them one after another as Particles does.
struct GatherLaneParticles {
  const double* position;              // 2 a lane
  const double* velocity;              // 2 a lane
  const double* deformation_gradient;  // 4 a lane
  const double* reference_volume;
};

// Where the update goes instead of GatherLaneSums (a batch of eight in
// place, which then leaves the sums and new_* unwritten: nobody reads them,
// and their 17 stores a half-batch were wasted): the particles' own arrays
// from the batch's first, in their layout (x_p and v_p 2 a lane, F_p 4, V_p
// 1); a null array is not written. Each lane's values are read before its
// own are written, so an array may be the one the update reads (x_p, v_p
// and F_p in place).
struct GatherLaneTargets {
  double* position = nullptr;
  double* velocity = nullptr;
  double* deformation_gradient = nullptr;
  double* volume = nullptr;
};

// The sums by lane: a_p, v_p^L and L_p (xx, yx, xy, yy: column by column);
// and with the update, as grid_to_particles forms them:
//   F_p <- (I + dt L_p) F_p, V_p = det(F_p) V_p0 (eqs. 1.74-1.75),
//   v_p + dt_kick a_p and x_p + dt v_p^L (eq. 1.76).
struct GatherLaneSums {
  alignas(64) double acceleration[2][kLanes];
  alignas(64) double velocity[2][kLanes];
  alignas(64) double velocity_gradient[4][kLanes];
  alignas(64) double new_position[2][kLanes];
  alignas(64) double new_velocity[2][kLanes];
  alignas(64) double new_deformation_gradient[4][kLanes];
  alignas(64) double new_volume[kLanes];
};

// `motion` holds four values a node (a_g, v_g^L) with room for a block's
// rows past the last node; `row` is the nodes along x; `particles`, where
// not null, asks for the update with steps dt and dt_kick.
struct GatherLaneGrid {
  const double* motion;
  std::ptrdiff_t row;
  const GatherLaneParticles* particles;
  double dt, kick;
  GatherLaneTargets targets = {};
};
void gather_lanes(const GatherLaneGrid& grid, const GatherLaneBatch& batch, GatherLaneSums& out);
// With a given build, which the CPU must have (cpu_has).
void gather_lanes(LaneBuild build, const GatherLaneGrid& grid, const GatherLaneBatch& batch, GatherLaneSums& out);

// Each build's own, compiled for its instructions (solver/CMakeLists.txt).
MPMVV_LANE_KERNEL(void gather_lanes(const GatherLaneGrid& grid, const GatherLaneBatch& batch, GatherLaneSums& out))

}  // namespace mpmvv
