// What particle to grid adds into: the node sums each thread keeps, how a
// stencil or a lane batch of eight reaches its nodes (for_each_stencil), and
// which particles a transfer takes. Read by the stages of solver/stages.hpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>
#include <vector>

#include "../gather_lanes.hpp"
#include "../geometry.hpp"
#include "../grid.hpp"
#include "../material/neo_hookean.hpp"
#include "../material/neo_hookean_lanes.hpp"
#include "../material/stress.hpp"
#include "../parallel.hpp"
#include "../particles.hpp"
#include "../scatter_lanes.hpp"
#include "../shape/cpdi_lanes.hpp"
#include "../shape/linear.hpp"
#include "../shape/stencil.hpp"

namespace mpmvv {

// ---------------------------------------------------------------- particle to grid

// Which node sums a transfer produces.
enum TransferField : unsigned {
  kMass = 1u,           // m_g, eq. 1.69
  kMomentum = 2u,       // m_g v_g, eq. 1.69
  kInternalForce = 4u,  // -f_g^int = -sum_p V_p sigma_p G_gp, eq. 1.70 (in r-z also
                        // -sum_p V_p sigma_theta <S_g / r> e_r, the hoop stress)
  kBodyForce = 8u,      // f_g^body = sum_p m_p b_p S_gp
  kAffineMomentum = 16u,  // with kMomentum (velocity_transfer = apic): each particle's momentum
                          // as its affine field, sum_p S_gp m_p (v_p + C_p (x_g - x_p)); the
                          // weights reproduce linear fields (sum_g S_gp x_g = x_p), so the
                          // total momentum is still sum_p m_p v_p
};

// A node's five sums side by side.
struct NodeSums {
  double mass, momentum_x, momentum_y, force_x, force_y;
};

// One scatter buffer per thread, each covering the whole grid with a node's
// five sums (mass, momentum x and y, force x and y). Each thread sizes its own
// when it first maps, in the layout of the stage (ScatterSums).
struct ScatterBuffers {
  static constexpr int kFields = 5;
  std::vector<std::vector<NodeSums>> by_node;  // ScatterSums<false>
  std::vector<std::vector<double>> by_field;   // ScatterSums<true>
  // The share of the last map's batches of lanes whose every stencil was a
  // block of nodes (particles_to_grid: a shape whose stencils may be blocks
  // adds by rows in a map that follows one where nearly all were).
  double block_batch_share = 0.0;

  void resize(int threads, std::size_t /*nodes: each thread sizes its own*/) {
    by_node.assign(std::size_t(threads), {});
    by_field.assign(std::size_t(threads), {});
  }
  int threads() const { return int(by_node.size()); }
};

// Where node i's sum k (NodeSums' order) lies in a thread's buffer. Node by
// node (ScatterBuffers::by_node: the five sums of a node side by side, one
// cache line) for a stage that adds one entry at a time; field by field
// (by_field: five arrays `stride` apart, with room past the last node for the
// row of a block at the grid's edge) for a stage that adds blocks by
// rows (scatter_lanes.hpp), where a block's row of nodes lies side by side in
// each array. Measured (callgrind, CPDI at A = 1, t = 0.40-0.44 s, where most
// domains stretch past a cell and go entry by entry): with its sums field by
// field that stage cost 2,262-2,303 instructions a particle-step (restricted
// pointers or a type of its own for each field did not help) against 2,128
// with NodeSums, whose five sums one address reaches. So a map adds by rows
// only where (nearly) all its stencils are blocks: uGIMP's and linear's
// always, CPDI's while its domains stay within a cell (scatter_by_rows).
template <bool ByField>
struct ScatterSums;

template <>
struct ScatterSums<false> {
  NodeSums* node;

  static std::vector<NodeSums>& own(ScatterBuffers& b, int thread) { return b.by_node[std::size_t(thread)]; }
  static std::size_t size_of(std::size_t nodes, std::ptrdiff_t) { return nodes; }
  explicit ScatterSums(std::vector<NodeSums>& v, std::size_t) : node(v.data()) {}
  double& operator()(int k, std::size_t i) const {
    NodeSums& n = node[i];
    return k == 0 ? n.mass : k == 1 ? n.momentum_x : k == 2 ? n.momentum_y : k == 3 ? n.force_x : n.force_y;
  }
};

template <>
struct ScatterSums<true> {
  double* data;
  std::size_t stride;  // the nodes, a row and 4

  static std::vector<double>& own(ScatterBuffers& b, int thread) { return b.by_field[std::size_t(thread)]; }
  static std::size_t stride_of(std::size_t nodes, std::ptrdiff_t row) { return nodes + std::size_t(row) + 4; }
  static std::size_t size_of(std::size_t nodes, std::ptrdiff_t row) {
    return ScatterBuffers::kFields * stride_of(nodes, row);
  }
  explicit ScatterSums(std::vector<double>& v, std::size_t nodes_stride) : data(v.data()), stride(nodes_stride) {}
  double& operator()(int k, std::size_t i) const { return data[std::size_t(k) * stride + i]; }
};

// True for a shape that evaluates its stencils by lanes (cpdi_lanes.hpp).
template <class Shape>
constexpr bool evaluates_lanes() {
  if constexpr (requires { Shape::lanes; }) return Shape::lanes;
  return false;
}

// True for a map of `Fields` by a shape whose lane kernel may leave a
// stencil as a block of nodes (lane_block_first), which particle-to-grid
// can add by rows (scatter_lanes.hpp): in plane strain, without the affine
// momentum.
template <unsigned Fields, class Shape>
constexpr bool may_scatter_by_rows() {
  if constexpr (evaluates_lanes<Shape>() && !(Fields & kAffineMomentum) && Shape::geometry != Geometry::axisymmetric)
    return requires(const Shape& s, const typename Shape::LaneBatch& b) { s.lane_block_first(b, 0); };
  return false;
}

// Every lane's block (lane_block_first) into `first_node`; true where every
// lane goes by rows (none is kNoBlock: lanes.hpp). All kLanes lanes, a short
// batch's spare lanes repeating its first (lanes.hpp: copied_lane_particle),
// in a loop without an exit: the map's loop that stopped at the first lane
// with no block cost 9 instructions a lane (callgrind; 4.8 a particle-step
// less with this one).
template <class Shape, class Node>
bool lane_blocks(const Shape& shape, const typename Shape::LaneBatch& batch, Node (&first_node)[kLanes]) {
  bool all = true;
  for (int l = 0; l < kLanes; ++l) {
    const Node block = Node(shape.lane_block_first(batch, l));
    first_node[l] = block;
    all &= block != kNoBlock;
  }
  return all;
}

// Whether a map adds by rows, decided once a map: always for a shape whose
// stencils are blocks but at the grid's edge (uGIMP: a domain of at most a
// cell's width; linear: the cell's 2 x 2 nodes; lane_blocks_only); for CPDI,
// where the last map found at least kRowsFromBlockShare of its batches all
// by rows. A batch that is not goes entry by entry into the sums field by
// field, which costs more than node by node (ScatterSums). Measured for CPDI
// (callgrind, instructions a particle-step of a whole step, by rows against
// node by node) while a domain stretched past a cell went entry by entry:
// 256 cells at A = 0.5, t = 0.02-0.04 s (every batch blocks) 1,104 against
// 1,162; 128 cells at A = 0.5, t = 0.40-0.44 s, 1,758 against 1,675; at A =
// 1, t = 0.40-0.44 s, 2,286 against 2,132. Such a domain now goes by rows
// too, by its corners' blocks (kByCorners), which leaves only a stencil
// that starts off the grid (its particle fails `inside`) out: on 256 cells
// at A = 0.5, t = 0.40-0.42 s, 1,387 instructions a particle-step by rows
// against 1,664 before. Both layouts add the same terms in the same order:
// the choice never changes a bit.
inline constexpr double kRowsFromBlockShare = 0.9;
inline constexpr std::size_t kBlockSample = 8;
template <class Shape>
bool scatter_by_rows(const ScatterBuffers& buffers) {
  if constexpr (requires { Shape::lane_blocks_only; })
    if (Shape::lane_blocks_only) return true;
  return buffers.block_batch_share >= kRowsFromBlockShare;
}

// Lane l's stencil as the shape's evaluate gives it (the kernel's bound of
// its sum_g |G_gp| is lane l of the shape's lane_gradient_bounds).
template <class Shape>
void list_lane(const Shape& shape, const typename Shape::LaneBatch& batch, int l, Stencil<Shape::stencil_size>& st) {
  int n = 0;
  shape.for_each_lane_entry(batch, l, [&](int node, double w, const Vec2& gradient) {
    st.node[n] = node;
    st.weight[n] = w;
    st.gradient[n] = gradient;
    ++n;
  });
  st.count = n;
}

// The batch a shape's lane kernel fills (an empty one for a shape without).
template <class Shape>
struct LaneBatchOf {
  struct type {};
};
template <class Shape>
  requires(evaluates_lanes<Shape>())
struct LaneBatchOf<Shape> {
  using type = typename Shape::LaneBatch;
};

// Called by every thread of a parallel region: each particle of [begin, end)
// the static schedule gives the thread, in order, with its stencil, as
//   visit(p, entries, stencil_of, gradient_bound)
// where entries(f) passes each entry to f(node, S_gp, G_gp, <S_g / r>_p),
// stencil_of() gives the stencil itself and gradient_bound is the lane
// kernel's bound of sum_g |G_gp| (negative where there is none). A shape that
// evaluates by lanes gives eight stencils at a time, its entries as the
// kernel left them, listed as a stencil only where stencil_of is called (the
// scan, where its bounds do not settle a speed). usable(p, inside) is asked
// first, with the shape's test of the particle's domain in the grid (from
// the lanes' own values where `for_scan`, as are the bounds); a particle it
// refuses is skipped. `on_lanes(first, count, gradient_bounds, batch)`,
// where given, sees each batch of kLanes particles before they are visited,
// with the kernel's bounds of the batch (lane_gradient_bounds; null without
// lanes or bounds) and the kernel's batch itself (an empty one without
// lanes): the particles go in batches then for any shape. A hook that
// returns true has dealt with the whole batch, whose particles are then not
// visited (the transfers by rows: scatter_lanes.hpp, gather_lanes.hpp).
// `after_lanes()`, where given, is called after each batch's visits. Ends
// with the threads' barrier.
struct NoLaneHook {};

// Lane l's entries in a batch (for_each_stencil): entries(f) as for any
// stencil, and the batch and lane themselves, for a stage that takes a
// block of nodes at once (particles_to_grid, scatter_lanes.hpp).
// The slots a lane kernel left in its batch (S_gp and G_gp by slot and lane:
// CPDI's, uGIMP's and linear's alike), for a transfer by rows.
template <class Batch, class Rows>
void take_slots(const Batch& batch, Rows& rows) {
  rows.weight = batch.out.weight;
  rows.gradient_x = batch.out.gradient_x;
  rows.gradient_y = batch.out.gradient_y;
  // Nodes along a block's side: linear's 2 (LinearLaneStencils::kBlock), else 3.
  if constexpr (requires { decltype(batch.out)::kBlock; }) rows.block = decltype(batch.out)::kBlock;
  else rows.block = 3;
  // CPDI's wide lanes (kByCorners): their corners' entries.
  if constexpr (requires { batch.out.corner_first; }) {
    rows.corner_weight = batch.out.wide_weight;
    rows.corner_gradient_x = batch.out.wide_gradient_x;
    rows.corner_gradient_y = batch.out.wide_gradient_y;
    rows.corner_first = batch.out.corner_first;
  }
}

template <class Shape>
struct LaneEntries {
  const Shape& shape;
  const typename Shape::LaneBatch& batch;
  int lane;
  int count;  // the batch's particles
  template <class F>
  void operator()(F&& f) const {
    shape.for_each_lane_entry(batch, lane, f);
  }
};

template <class Shape, class Usable, class Visit, class OnLanes = NoLaneHook, class AfterLanes = NoLaneHook>
void for_each_stencil(const Shape& shape, std::size_t begin, std::size_t end, bool for_scan, Usable usable,
                      Visit visit, OnLanes on_lanes = {}, AfterLanes after_lanes = {}) {
  constexpr bool lanes = evaluates_lanes<Shape>();
  constexpr bool hooked = !std::is_same_v<OnLanes, NoLaneHook>;
  Stencil<Shape::stencil_size> s;
  auto stencil_s = [&]() -> const Stencil<Shape::stencil_size>& { return s; };
  auto one = [&](std::size_t p) {
    if (!usable(p, [&] { return shape.inside(p); })) return;
    shape.evaluate(p, s);
    visit(p, entries_of(s), stencil_s, -1.0);
  };
  if constexpr (!lanes && !hooked) {
#pragma omp for schedule(static)
    for (std::size_t p = begin; p < end; ++p) one(p);
  } else {
    // The static schedule's block, kLanes at a time (parallel.hpp: static_block).
    const auto [first, last] = static_block(begin, end);
    [[maybe_unused]] typename LaneBatchOf<Shape>::type batch;
    for (std::size_t p0 = first; p0 < last; p0 += kLanes) {
      const int count = int(std::min<std::size_t>(kLanes, last - p0));
      const double* bounds = nullptr;
      if constexpr (lanes) {
        shape.compute_lanes(p0, count, batch, for_scan);
        bounds = shape.lane_gradient_bounds(batch);
      }
      if constexpr (hooked) {
        // A hook that returns true has taken the whole batch itself.
        if constexpr (std::is_same_v<decltype(on_lanes(p0, count, bounds, batch)), bool>) {
          if (on_lanes(p0, count, bounds, batch)) continue;
        } else {
          on_lanes(p0, count, bounds, batch);
        }
      }
      for (int l = 0; l < count; ++l) {
        const std::size_t p = p0 + std::size_t(l);
        if constexpr (lanes) {
          if (!usable(p, [&] { return shape.lane_inside(batch, l); })) continue;
          bool listed = false;
          auto stencil_of = [&]() -> const Stencil<Shape::stencil_size>& {
            if (!listed) list_lane(shape, batch, l, s);
            listed = true;
            return s;
          };
          visit(p, LaneEntries<Shape>{shape, batch, l, count}, stencil_of, bounds ? bounds[l] : -1.0);
        } else {
          one(p);
        }
      }
      if constexpr (!std::is_same_v<AfterLanes, NoLaneHook>) after_lanes();
    }
#pragma omp barrier
  }
}

// A range of particles [first, last): one body of a scene with several, which
// keep their particles contiguous. The whole set by default.
struct ParticleRange {
  std::size_t first = 0;
  std::size_t last = static_cast<std::size_t>(-1);
  std::size_t end(const Particles& P) const { return std::min(last, P.size()); }
};

// A map without a scan (ScanInMap, below).
struct NoScan {};

// The scan's screen of a batch of lanes (ScanInMap::screen_lanes), where it
// makes one: the verdicts of particles first, ..., first + kLanes - 1.
struct ScanScreen {
  bool valid = false;
  std::size_t first = 0;
  NeoHookeanScanLaneVerdict verdict;
};

}  // namespace mpmvv
