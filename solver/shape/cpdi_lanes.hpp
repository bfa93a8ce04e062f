// The CPDI stencil of eight particles at once, each in a lane of one vector:
// the same sums as CpdiShapeT::evaluate (cpdi.hpp, after
// 002_c3305cb8b1bc1490.txt eqs. 1.95-1.100), for plane-strain parallelogram
// domains, with every corner's bilinear weights summed into the 3 x 3 nodes
// from the domain's lowest corner cell.
//
// Why lanes: a particle's stencil is four corners of the same arithmetic,
// whose merge into shared nodes indexes a small array by each corner's cell
// and so chains every sum through memory. Written instead as a sum over the
// nine nodes of selected corner weights (a corner that does not reach a node
// adds zero), it has no index that depends on the data and runs on as many
// particles as the vector holds (lanes.hpp: built for AVX-512, AVX2 and any
// x86-64). Every product and sum is the one evaluate forms, in the same
// order, so the stencils are the same to the last bit (zero terms added to a
// sum change nothing).
//
// The kernel reads no memory by a lane's values, so a lane may hold any
// state, NaN included: the caller tests the particle's health with the
// kernel's own `inside` before it lists the stencil.
//
// A lane whose corners span more than 2 x 2 cells (a domain stretched past a
// cell) takes evaluate's other form: four entries per corner, not merged,
// which the transfers by rows take as four blocks of 2 x 2 nodes.
#pragma once

#include "../lanes.hpp"

namespace mpmvv {

// The grid and the method's factors, the same for every lane.
struct CpdiLaneGrid {
  double origin_x, origin_y, h;
  int cells_x, cells_y;        // ghost layers included
  int nodes_x;                 // GridGeometry::nodes_x, for block_first
  double gradient_scale;       // CpdiShapeT::gradient_scale
  double weight_skew;          // CpdiShapeT::weight_skew
  double wall_lower_x, wall_lower_y, wall_upper_x, wall_upper_y;  // GridGeometry::wall_lower, wall_upper
  bool for_scan;               // the time-step scan reads the batch: fill inside (four divisions
                               // a lane) and gradient_bound, else -1 there
  double shear_sign = 1.0;     // CpdiShapeT::shear_sign
};

// Eight particles' centres x_p and domains s_p = [r_1 r_2] = F_p diag(l_p)
// (eq. 1.97), read in place: the particles' own arrays from the batch's
// first (Particles::position, deformation_gradient column by column,
// half_size; tensor.hpp: values_of). CpdiLaneCopy holds them otherwise.
struct CpdiLaneInput {
  const double* position;              // 2 a lane
  const double* deformation_gradient;  // 4 a lane
  const double* half_size;             // 2 a lane
};

// The same for a batch of fewer than eight particles (its spare lanes
// repeating the first), or for domains of another form (turned, F_p A_p; or
// no F_p): s_p itself in F_p's place and half sizes of 1, which the kernel's
// products s_p l_p leave as they are, to the bit.
struct CpdiLaneCopy {
  alignas(64) double position[2 * kLanes];
  alignas(64) double deformation_gradient[4 * kLanes];
  alignas(64) double half_size[2 * kLanes];
};

// S_gp and G_gp of node (i0 + a, j0 + b) in slot a + 3 b, and the spans of
// the corners' cells. `gradient_bound` is an upper bound of sum_g |G_gp|
// over the nine, for the time-step scan (stages.hpp:
// entry_gradient_sum_bound, the same bound), where CpdiLaneGrid::for_scan.
//
// A lane with a span over 1 is `wide`: its entries are evaluate's sixteen,
// corner c's in slots 4 c + k, at the nodes (i, j), (i + 1, j), (i, j + 1),
// (i + 1, j + 1) of the corner's cell, node (i, j) in corner_first, and its
// gradient_bound is the octagon bound over the nodes they reach, each node's
// entries summed in the order merged_gradients sums them (stencil.hpp), so
// it bounds the scan's stiffening (stages.hpp: gradient_sum) and not the
// looser sum over entries; where a span is over 2 (nodes past a 4 x 4
// block), the bound over its sixteen entries as listed, the value and bits
// of stencil.hpp's entry_gradient_sum_bound, which the scan would form from
// the listed stencil. The wide arrays are filled only for batches of W
// lanes that hold a wide one.
struct CpdiLaneStencils {
  alignas(64) double weight[9][kLanes];
  alignas(64) double gradient_x[9][kLanes];
  alignas(64) double gradient_y[9][kLanes];
  alignas(64) double gradient_bound[kLanes];
  alignas(64) double wide_weight[16][kLanes];
  alignas(64) double wide_gradient_x[16][kLanes];
  alignas(64) double wide_gradient_y[16][kLanes];
  alignas(32) int corner_first[4][kLanes];  // GridGeometry::node of the corner's cell's first node
  // CpdiShapeT::inside: the centre lies between the walls and the domain's
  // bounding box, x_p -+ (|r_1| + |r_2|) along each axis, in the grid's
  // cells; only where CpdiLaneGrid::for_scan asks for it.
  alignas(32) int inside[kLanes];
  alignas(32) int i0[kLanes];
  alignas(32) int j0[kLanes];
  alignas(32) int span_i[kLanes];
  alignas(32) int span_j[kLanes];
  // CpdiShapeT::lane_block_first: the node (i0, j0) where the lane's nodes
  // are a 3 x 3 block (spans of 1 at most), kByCorners for a wide lane
  // (lanes.hpp), and kNoBlock where a corner's cell is off the grid (i0 or
  // j0 negative: the particle fails `inside`); the transfers by rows look at
  // every lane of every batch, and a test of four of the arrays above lane
  // by lane cost 25 instructions a lane (callgrind).
  alignas(32) int block_first[kLanes];
};

// With the build the kernels run (lane_build), or with a given one, which
// the CPU must have (cpu_has).
void cpdi_lane_stencils(const CpdiLaneGrid& grid, const CpdiLaneInput& in, CpdiLaneStencils& out);
void cpdi_lane_stencils(LaneBuild build, const CpdiLaneGrid& grid, const CpdiLaneInput& in, CpdiLaneStencils& out);

// Each build's own, compiled for its instructions (solver/CMakeLists.txt).
MPMVV_LANE_KERNEL(void cpdi_lane_stencils(const CpdiLaneGrid& grid, const CpdiLaneInput& in, CpdiLaneStencils& out))

}  // namespace mpmvv
