// The bilinear stencil of eight particles at once (lanes.hpp): the same
// weights and gradients as bilinear_cell (linear.hpp, eqs. 1.86-1.89 of
// 002_c3305cb8b1bc1490.txt), plane strain, to the last bit.
//
// Why lanes: linear MPM's transfers were scalar code, a node at a time
// (callgrind, 256-cell ring: particle-to-grid 339 and grid-to-particle 196
// instructions a particle-step); in lanes its stencils go by rows of nodes
// through the same kernels as uGIMP's and CPDI's (scatter_lanes.hpp,
// gather_lanes.hpp), two rows of two nodes a particle.
#pragma once

#include "../lanes.hpp"

namespace mpmvv {

struct LinearLaneGrid {
  double origin_x, origin_y, h;
  int cells_x, cells_y;  // ghost layers included
  int nodes_x;
  double wall_lower_x, wall_lower_y, wall_upper_x, wall_upper_y;  // GridGeometry::wall_lower, wall_upper
  double gradient_scale = 1.0;  // LinearShapeT::gradient_scale
};

// Eight particles' positions x_p, read in place from the batch's first, or
// a copy for a batch of fewer than eight (the spare lanes repeating the first).
struct LinearLaneCopy {
  alignas(64) double position[2 * kLanes];
};

// S_gp and G_gp of node (i + a, j + b) in slot a + 3 b, a and b 0 or 1, with
// (i, j) the cell holding x_p, in the 3 x 3 layout of the transfers by rows
// (scatter_lanes.hpp), which read only these four slots of a block of
// kBlock x kBlock nodes. first_node is node
// (i, j), with i and j at least 0 (a lane outside the grid, NaN included,
// names a node of it; the caller tests `inside` before it uses the lane).
struct LinearLaneStencils {
  static constexpr int kBlock = 2;  // nodes along each side of a stencil's block
  alignas(64) double weight[9][kLanes];
  alignas(64) double gradient_x[9][kLanes];
  alignas(64) double gradient_y[9][kLanes];
  alignas(32) int first_node[kLanes];
  alignas(32) int inside[kLanes];  // inside_walls (stencil.hpp), for the time-step scan's health test
};

// With the build the kernels run (lane_build), or with a given one, which
// the CPU must have (cpu_has).
void linear_lane_stencils(const LinearLaneGrid& grid, const double* position, LinearLaneStencils& out);
void linear_lane_stencils(LaneBuild build, const LinearLaneGrid& grid, const double* position,
                          LinearLaneStencils& out);

// Each build's own, compiled for its instructions (solver/CMakeLists.txt).
MPMVV_LANE_KERNEL(void linear_lane_stencils(const LinearLaneGrid& grid, const double* position,
                                            LinearLaneStencils& out))

}  // namespace mpmvv
