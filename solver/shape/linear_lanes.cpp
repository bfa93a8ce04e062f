// The lane kernel of linear_lanes.hpp (lane_vectors.hpp says how it is built).
// Each line is the scalar line of bilinear_cell (linear.hpp) it repeats.
#include "linear_lanes.hpp"

#include "../lane_vectors.hpp"

namespace mpmvv {

namespace {

using namespace lanes::MPMVV_LANE_BUILD_NS;

struct LinearKernel {
  using Grid = LinearLaneGrid;
  using In = const double*;
  using Out = LinearLaneStencils;

  template <int W>
  MPMVV_LANE_INLINE static void body(const LinearLaneGrid& g, const double* const& position, LinearLaneStencils& out,
                                     int l0) {
    using Lanes = typename Width<W>::Lanes;
    using Mask = typename Width<W>::Mask;
    using Ints = typename Width<W>::Ints;
    const Ints none = {};
    Lanes x[2];
    load_interleaved(position + 2 * l0, x);
    // inside_walls; NaN fails.
    const Mask inside =
        (x[0] >= g.wall_lower_x) & (x[0] <= g.wall_upper_x) & (x[1] >= g.wall_lower_y) & (x[1] <= g.wall_upper_y);
    store(out.inside + l0, to_ints<Ints>(inside));
    const Lanes xi_x = (x[0] - g.origin_x) / g.h, xi_y = (x[1] - g.origin_y) / g.h;  // grid_coordinate
    // cell_index, and at least 0 so that a lane outside names a node.
    const Ints i = lane_max(lane_min(__builtin_convertvector(xi_x, Ints), none + (g.cells_x - 1)), none);
    const Ints j = lane_max(lane_min(__builtin_convertvector(xi_y, Ints), none + (g.cells_y - 1)), none);
    store(out.first_node + l0, j * g.nodes_x + i);  // GridGeometry::node(i, j)
    const Lanes fx = xi_x - to_doubles<Lanes>(i), fy = xi_y - to_doubles<Lanes>(j);
    const Lanes gx = 1.0 - fx, gy = 1.0 - fy;
    const double inv_h = g.gradient_scale / g.h;
    // Slots 0, 1, 3, 4: bilinear_cell's entries 0-3, each stored as it is
    // formed (arrays of them were copied through the stack).
    store(out.weight[0] + l0, gx * gy);
    store(out.gradient_x[0] + l0, -gy * inv_h);
    store(out.gradient_y[0] + l0, -gx * inv_h);
    store(out.weight[1] + l0, fx * gy);
    store(out.gradient_x[1] + l0, gy * inv_h);
    store(out.gradient_y[1] + l0, -fx * inv_h);
    store(out.weight[3] + l0, gx * fy);
    store(out.gradient_x[3] + l0, -fy * inv_h);
    store(out.gradient_y[3] + l0, gx * inv_h);
    store(out.weight[4] + l0, fx * fy);
    store(out.gradient_x[4] + l0, fy * inv_h);
    store(out.gradient_y[4] + l0, fx * inv_h);
  }
};

}  // namespace

namespace lanes::MPMVV_LANE_BUILD_NS {
void linear_lane_stencils(const LinearLaneGrid& grid, const double* position, LinearLaneStencils& out) {
  run<LinearKernel>(grid, position, out);
}
}  // namespace lanes::MPMVV_LANE_BUILD_NS

#if defined(MPMVV_LANE_DISPATCH)
MPMVV_LANE_DISPATCH_OF(linear_lane_stencils,
                       (const LinearLaneGrid& grid, const double* position, LinearLaneStencils& out),
                       (grid, position, out))
#endif

}  // namespace mpmvv
