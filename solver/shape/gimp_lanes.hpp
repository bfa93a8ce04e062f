// The uGIMP stencil of eight particles at once (lanes.hpp): the same weights
// and gradients as GimpShapeT::evaluate (gimp.hpp, eqs. 1.91-1.92 of
// 002_c3305cb8b1bc1490.txt and their tensor product), plane strain, to the
// last bit. Each lane picks the operands of the piece of the 1D weight that
// the scalar code's first true test picks (gimp_lanes.cpp), so the lanes
// need no branch.
#pragma once

#include "../lanes.hpp"

namespace mpmvv {

struct GimpLaneGrid {
  double origin_x, origin_y, h;
  int cells_x, cells_y;  // ghost layers included
  int nodes_x;           // GridGeometry::nodes_x, for block_first
  double wall_lower_x, wall_lower_y, wall_upper_x, wall_upper_y;  // GridGeometry::wall_lower, wall_upper
  double upper_x, upper_y;                                        // GridGeometry::upper
  double gradient_scale = 1.0;                                    // GimpShapeT::gradient_scale
};

// Eight particles' centres x_p and half-sizes l_p, read in place: the
// particles' own arrays from the batch's first (as for CPDI, cpdi_lanes.hpp).
struct GimpLaneInput {
  const double* position;   // 2 a lane
  const double* half_size;  // 2 a lane
};

// The same for a batch of fewer than eight, the spare lanes repeating the first.
struct GimpLaneCopy {
  alignas(64) double position[2 * kLanes];
  alignas(64) double half_size[2 * kLanes];
};

// S_gp and G_gp of node (node_i[a], node_j[b]) in slot a + 3 b.
struct GimpLaneStencils {
  alignas(64) double weight[9][kLanes];
  alignas(64) double gradient_x[9][kLanes];
  alignas(64) double gradient_y[9][kLanes];
  alignas(32) int node_i[3][kLanes];
  alignas(32) int node_j[3][kLanes];
  alignas(32) int inside[kLanes];  // GimpShapeT::inside, for the time-step scan's health test
  // GimpShapeT::lane_block_first: node (node_i[0], node_j[0]) where the three
  // nodes along each axis follow one another (none held at the grid's edge),
  // else -1; the transfers by rows look at every lane of every batch.
  alignas(32) int block_first[kLanes];
};

// With the build the kernels run (lane_build), or with a given one, which
// the CPU must have (cpu_has).
void gimp_lane_stencils(const GimpLaneGrid& grid, const GimpLaneInput& in, GimpLaneStencils& out);
void gimp_lane_stencils(LaneBuild build, const GimpLaneGrid& grid, const GimpLaneInput& in, GimpLaneStencils& out);

// Each build's own, compiled for its instructions (solver/CMakeLists.txt).
MPMVV_LANE_KERNEL(void gimp_lane_stencils(const GimpLaneGrid& grid, const GimpLaneInput& in, GimpLaneStencils& out))

}  // namespace mpmvv
