// The stages of an explicit MPM step as free functions over particle and grid
// arrays (002_c3305cb8b1bc1490.txt section 1.5). A stepper composes them in the
// order of its stress-update scheme. Every choice (shape function, material,
// which fields move) is a template parameter: it is made once per stage, never
// per particle.
//
// Threads: particles are split statically over threads. Particle-to-grid
// scatters into one private buffer per thread and the buffers are summed node
// by node in thread order, so a run is bit-for-bit repeatable for a given
// thread count.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>
#include <vector>

#include "gather_lanes.hpp"
#include "geometry.hpp"
#include "grid.hpp"
#include "material/neo_hookean.hpp"
#include "material/neo_hookean_lanes.hpp"
#include "material/stress.hpp"
#include "parallel.hpp"
#include "particles.hpp"
#include "scatter_lanes.hpp"
#include "shape/cpdi_lanes.hpp"
#include "shape/linear.hpp"
#include "shape/stencil.hpp"

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

// particles_to_grid (below) with its sums in the layout ByRows.
template <unsigned Fields, bool ByRows, class Shape, class Scan>
void map_to_grid(const Shape& shape, const Particles& P, ScatterBuffers& buffers, GridFields& g, ParticleRange range,
                 const GridGeometry* grid, Scan* scan) {
  constexpr bool scanning = !std::is_same_v<Scan, NoScan>;
  constexpr bool with_mass = Fields & kMass;
  constexpr bool with_momentum = Fields & kMomentum;
  constexpr bool with_affine = Fields & kAffineMomentum;
  static_assert(!with_affine || with_momentum, "the affine field is a part of the momentum");
  constexpr bool with_internal = Fields & kInternalForce;
  constexpr bool with_body = Fields & kBodyForce;
  constexpr bool with_force = with_internal || with_body;
  constexpr bool axisymmetric = Shape::geometry == Geometry::axisymmetric;
  // Blocks by rows into sums field by field (scatter_lanes.hpp), or one entry
  // at a time into sums node by node (ScatterSums); the batches that are all
  // blocks are counted either way, for the next map's choice.
  constexpr bool counts_blocks = may_scatter_by_rows<Fields, Shape>();
  constexpr bool by_rows = ByRows;
  static_assert(!by_rows || counts_blocks);
  using Sums = ScatterSums<by_rows>;
  std::size_t batches = 0, block_batches = 0;
  const std::size_t n = range.end(P);
  const std::size_t nodes = g.mass.size();
  const int threads = buffers.threads();
  std::ptrdiff_t row = 0;
  if constexpr (by_rows) row = shape.grid->nodes_x();
  [[maybe_unused]] std::size_t stride = nodes;
  if constexpr (by_rows) stride = Sums::stride_of(nodes, row);

#pragma omp parallel num_threads(threads)
  {
    auto& own = Sums::own(buffers, thread_id());
    using Value = typename std::decay_t<decltype(own)>::value_type;
    if (own.size() != Sums::size_of(nodes, row)) own.assign(Sums::size_of(nodes, row), Value{});
    else std::fill(own.begin(), own.end(), Value{});
    const Sums sum(own, stride);
    [[maybe_unused]] ScatterLaneBatch rows;  // the batch's particles that go by rows, not yet added
    [[maybe_unused]] bool batch_by_rows = false;  // every particle of the batch at hand
    [[maybe_unused]] const ScatterFields fields{with_mass, with_momentum, with_internal, with_body};
    [[maybe_unused]] const ScatterParticles particles{
        P.mass.data(), values_of(P.velocity.data()), P.volume.data(), values_of(P.stress.data()),
        with_body ? values_of(P.body_force.data()) : nullptr};
    auto add_rows = [&] {
      if constexpr (by_rows)
        if (rows.pending != 0)
          scatter_lanes(fields, particles, rows,
                        ScatterRows{&sum(0, 0), &sum(1, 0), &sum(2, 0), &sum(3, 0), &sum(4, 0), row});
    };
    [[maybe_unused]] double max_speed = 0.0;
    [[maybe_unused]] std::size_t first_unhealthy = P.size();
    [[maybe_unused]] std::size_t own_batches = 0, own_block_batches = 0, seen_batches = 0;
    [[maybe_unused]] ScanScreen screen;  // the scan's look at the batch of lanes at hand
    // `entries(f)` passes each entry of the particle's stencil to f;
    // `stencil_of()` gives the stencil itself, which the scan asks for only
    // where its bounds do not settle the particle's speed.
    auto map = [&](std::size_t p, auto&& entries, auto&& stencil_of, double gradient_bound) {
      if constexpr (scanning)
        max_speed = std::max(max_speed, scan->speed(p, stencil_of, max_speed, gradient_bound, screen));
      if constexpr (by_rows && requires { entries.lane; }) {
        // In a batch whose every particle goes by rows (its blocks noted by
        // the batch's hook), added with the batch's others (add_rows), the
        // same sums; a batch with a lane whose nodes are no block (a node
        // held at the grid's edge) goes entry by entry whole.
        if (batch_by_rows) {
          const int l = entries.lane;
          if (rows.pending == 0) {
            take_slots(entries.batch, rows);
            rows.first = p - std::size_t(l);
          }
          rows.pending |= 1u << l;
          return;
        }
      }
      const double m = P.mass[p];
      Vec2 momentum = Vec2::Zero(), body = Vec2::Zero();
      Mat2 volume_stress = Mat2::Zero();
      double volume_hoop_stress = 0.0;
      if constexpr (with_momentum) momentum = m * P.velocity[p];
      if constexpr (with_body) body = m * P.body_force[p];
      if constexpr (with_internal) volume_stress = P.volume[p] * P.stress[p];
      if constexpr (with_internal && axisymmetric) volume_hoop_stress = P.volume[p] * P.hoop_stress[p];
      entries([&](int i, double w, const Vec2& gradient, const double& hoop = 0.0) {
        if constexpr (with_mass) sum(0, i) += w * m;
        if constexpr (with_affine) {
          const Vec2 affine = momentum + m * (P.affine_velocity[p] * (grid->node_position(i) - P.position[p]));
          sum(1, i) += w * affine.x();
          sum(2, i) += w * affine.y();
        } else if constexpr (with_momentum) {
          sum(1, i) += w * momentum.x();
          sum(2, i) += w * momentum.y();
        }
        if constexpr (with_force) {
          Vec2 f = Vec2::Zero();
          if constexpr (with_internal) f -= volume_stress * gradient;
          if constexpr (with_internal && axisymmetric) f.x() -= volume_hoop_stress * hoop;
          if constexpr (with_body) f += w * body;
          sum(3, i) += f.x();
          sum(4, i) += f.y();
        }
      });
    };
    // A particle the scan finds unhealthy is reported and skipped; `inside`
    // is the shape's test of it (the lanes have it from their kernel).
    auto usable = [&](std::size_t p, auto inside) {
      if constexpr (scanning) {
        if (!scan->healthy(p, inside, screen)) {
          first_unhealthy = std::min(first_unhealthy, p);
          return false;
        }
      }
      return true;
    };
    for_each_stencil(
        shape, range.first, n, scanning, usable, map,
        [&](std::size_t first, int count, const double* gradient_bounds, auto&& batch) {
          if constexpr (scanning) scan->screen_lanes(first, count, gradient_bounds, max_speed, screen);
          // A batch whose every particle goes by rows and which the scan's
          // screen finds healthy, inside and unable to raise the largest
          // speed (its speed() would be 0, its healthy() true) is added
          // whole, without a visit of each of its particles.
          // Node by node the share is sampled, one batch in kBlockSample
          // (testing every batch cost 12 instructions a particle-step where
          // few are blocks, callgrind); by rows every batch is looked at anyway.
          if constexpr (counts_blocks) {
            if (by_rows || seen_batches++ % kBlockSample == 0) {
              const bool blocks = lane_blocks(shape, batch, rows.first_node);
              ++own_batches;
              own_block_batches += blocks;
              if constexpr (by_rows) batch_by_rows = blocks;
            }
          }
          if constexpr (by_rows) {
            if (!batch_by_rows) return false;
            if constexpr (scanning) {
              if (!screen.valid) return false;
              for (int l = 0; l < count; ++l)
                if (screen.verdict.sound[l] == 0 || screen.verdict.may_set_speed[l] != 0 ||
                    !shape.lane_inside(batch, l))
                  return false;
            }
            take_slots(batch, rows);
            rows.first = first;
            rows.pending = (1u << count) - 1u;
            add_rows();
            return true;
          }
          return false;
        },
        add_rows);
    if constexpr (scanning) {
      // A largest and a lowest: the same whatever order the threads come in.
#pragma omp critical
      {
        scan->result.max_signal_speed = std::max(scan->result.max_signal_speed, max_speed);
        scan->result.first_unhealthy = std::min(scan->result.first_unhealthy, first_unhealthy);
      }
    }
    if constexpr (counts_blocks) {
#pragma omp atomic
      batches += own_batches;
#pragma omp atomic
      block_batches += own_block_batches;
    }
    // The barrier after the particles above: all buffers are complete.
#pragma omp for schedule(static)
    for (std::size_t i = 0; i < nodes; ++i) {
      double total[ScatterBuffers::kFields];
      const Sums first(Sums::own(buffers, 0), stride);
      for (int k = 0; k < ScatterBuffers::kFields; ++k) total[k] = first(k, i);
      for (int t = 1; t < threads; ++t) {
        const Sums other(Sums::own(buffers, t), stride);
        for (int k = 0; k < ScatterBuffers::kFields; ++k) total[k] += other(k, i);
      }
      if constexpr (with_mass) g.mass[i] = total[0];
      if constexpr (with_momentum) g.momentum[i] = Vec2(total[1], total[2]);
      if constexpr (with_force) g.force[i] = Vec2(total[3], total[4]);
    }
  }
  if constexpr (counts_blocks) buffers.block_batch_share = batches > 0 ? double(block_batches) / double(batches) : 0.0;
}

// Sums the particle quantities selected by `Fields` onto the grid and stores
// them in `g`, overwriting those node fields (the others are left as they are).
// kAffineMomentum reads the node positions from `grid`. With `scan` (a
// ScanInMap) the map also scans the state it weighs, into scan->result. The
// layout of the sums is chosen once a map (scatter_by_rows).
template <unsigned Fields, class Shape, class Scan = NoScan>
void particles_to_grid(const Shape& shape, const Particles& P, ScatterBuffers& buffers, GridFields& g,
                       ParticleRange range = {}, const GridGeometry* grid = nullptr, Scan* scan = nullptr) {
  if constexpr (may_scatter_by_rows<Fields, Shape>())
    if (scatter_by_rows<Shape>(buffers)) return map_to_grid<Fields, true>(shape, P, buffers, g, range, grid, scan);
  map_to_grid<Fields, false>(shape, P, buffers, g, range, grid, scan);
}

// ---------------------------------------------------------------- grid update

// a_g = f_g / m_g (eq. 1.71) and v_g^L = v_g + a_g dt_kick (eq. 1.72). The
// kick is the step itself, or under central differences the mean of the steps
// on either side of t_n. Nodes no particle reaches carry no mass and stay at rest.
inline void update_grid_motion(GridFields& g, double kick) {
  const std::size_t nodes = g.mass.size();
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < nodes; ++i) {
    if (g.mass[i] > 0.0) {
      const double inv_m = 1.0 / g.mass[i];
      g.acceleration[i] = g.force[i] * inv_m;
      g.velocity[i] = g.momentum[i] * inv_m + g.acceleration[i] * kick;
    } else {
      g.acceleration[i].setZero();
      g.velocity[i].setZero();
    }
  }
}

// v_g = (m_g v_g) / m_g without advancing it: the velocity a USF step takes its
// gradient from, and the remapped velocity of MUSL.
inline void grid_velocity_from_momentum(GridFields& g) {
  const std::size_t nodes = g.mass.size();
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < nodes; ++i)
    g.velocity[i] = g.mass[i] > 0.0 ? Vec2(g.momentum[i] / g.mass[i]) : Vec2::Zero();
}

// Symmetry (roller) walls on the four sides: nodes on a wall keep no velocity
// and no acceleration normal to it, tangential motion is free. A ghost node k
// cells beyond a wall takes the mirror image of the node k cells inside: the
// tangential components equal, the normal component negated. In r-z the wall
// r = 0 is the axis and the same mirror is the axisymmetry condition. The
// x-walls are mirrored first over all rows, then the y-walls over all columns,
// so corner ghosts mirror in both. `swapped` is a deliberate fault
// (faults.hpp: swapped-walls): each wall treats the tangential component as
// its normal one.
inline void apply_walls(const GridGeometry& grid, GridFields& g, bool swapped = false) {
  const int nx = grid.nodes_x(), ny = grid.nodes_y(), ghost = grid.ghost_layers;
  const int x_walls[2] = {ghost, nx - 1 - ghost}, y_walls[2] = {ghost, ny - 1 - ghost};
  const int x_normal = swapped ? 1 : 0, y_normal = 1 - x_normal;
  auto mirror = [&g](int from, int to, int normal) {
    g.velocity[to] = g.velocity[from];
    g.acceleration[to] = g.acceleration[from];
    g.velocity[to][normal] = -g.velocity[from][normal];
    g.acceleration[to][normal] = -g.acceleration[from][normal];
  };
  for (int j = 0; j < ny; ++j) {
    for (int w : x_walls) {
      g.velocity[grid.node(w, j)][x_normal] = 0.0;
      g.acceleration[grid.node(w, j)][x_normal] = 0.0;
    }
    for (int k = 1; k <= ghost; ++k) {
      mirror(grid.node(x_walls[0] + k, j), grid.node(x_walls[0] - k, j), x_normal);
      mirror(grid.node(x_walls[1] - k, j), grid.node(x_walls[1] + k, j), x_normal);
    }
  }
  for (int i = 0; i < nx; ++i) {
    for (int w : y_walls) {
      g.velocity[grid.node(i, w)][y_normal] = 0.0;
      g.acceleration[grid.node(i, w)][y_normal] = 0.0;
    }
    for (int k = 1; k <= ghost; ++k) {
      mirror(grid.node(i, y_walls[0] + k), grid.node(i, y_walls[0] - k), y_normal);
      mirror(grid.node(i, y_walls[1] - k), grid.node(i, y_walls[1] + k), y_normal);
    }
  }
}

// ---------------------------------------------------------------- grid to particle

// What a grid-to-particle transfer updates.
enum ParticleUpdate : unsigned {
  kVelocity = 1u,     // v_p += dt_kick sum_g S_gp a_g (eq. 1.76)
  kPosition = 2u,     // x_p += dt sum_g S_gp v_g^L (eq. 1.76)
  kDeformation = 4u,  // L_p = sum_g v_g (x) G_gp (eq. 1.73); F_p <- (I + dt L_p) F_p
                      // (eq. 1.74) and V_p = J_p V_p0 (eq. 1.75: the product of the
                      // increments' determinants, without its round-off drift).
                      // With positions moved by x += dt sum S v (eq. 1.76), I + dt L
                      // is the exact gradient of that map, so F follows the particles.
                      // In r-z also the hoop rate v_r / r = sum_g <S_g / r> v_gr:
                      // F_theta <- (1 + dt v_r / r) F_theta, J_p = det(F_p) F_theta.
  kAffine = 8u,       // with kVelocity (velocity_transfer = apic): v_p = sum_g S_gp v_g^L and
                      // C_p = sum_g v_g^L (x) G_gp in place of the increment of eq. 1.76
};

// Every update reads the grid at the particle's position at the start of the
// stage. New positions go to `position_out`, which may be P.position itself
// (each particle reads its own position before writing it) or, when a later
// stage still needs the old positions, another array.
//
// A shape whose lane kernel leaves blocks of nodes (3 x 3; linear's 2 x 2)
// takes its sums by lanes (gather_lanes.hpp) from the nodes' a_g and v_g^L
// packed side by side into `motion` (a scratch the caller keeps between
// steps; one of its own without).
template <unsigned Updates, class Shape>
void grid_to_particles(const Shape& shape, const GridFields& g, Particles& P, double dt, double kick,
                       Vec2* position_out = nullptr, ParticleRange range = {}, std::vector<double>* motion = nullptr) {
  constexpr bool with_velocity = Updates & kVelocity;
  constexpr bool with_position = Updates & kPosition;
  constexpr bool with_deformation = Updates & kDeformation;
  constexpr bool with_affine = Updates & kAffine;
  static_assert(!with_affine || with_velocity, "the affine field is a velocity update");
  constexpr bool axisymmetric = Shape::geometry == Geometry::axisymmetric;
  constexpr bool by_rows = evaluates_lanes<Shape>() && !axisymmetric;
  if (position_out == nullptr) position_out = P.position.data();
  const std::size_t n = range.end(P);
  [[maybe_unused]] std::vector<double> own_motion;
  [[maybe_unused]] std::ptrdiff_t row = 0;
  if constexpr (by_rows) {
    // Four values a node, and rows of zeros past the last for a block at the
    // grid's edge (as the sums field by field: ScatterSums).
    row = shape.grid->nodes_x();
    if (motion == nullptr) motion = &own_motion;
    const std::size_t size = 4 * ScatterSums<true>::stride_of(g.mass.size(), row);
    if (motion->size() != size) motion->assign(size, 0.0);
  }
#pragma omp parallel
  {
    [[maybe_unused]] GatherLaneBatch lane_batch;
    [[maybe_unused]] GatherLaneSums lane_sums;
    [[maybe_unused]] bool batch_by_rows = false;  // lane_sums hold the batch at hand
    // The batch's particles from `first`, in place for a whole batch, else
    // copied (the spare lanes repeating the first; lanes.hpp).
    [[maybe_unused]] GatherLaneParticles in_place;
    [[maybe_unused]] struct {
      alignas(64) double position[2 * kLanes], velocity[2 * kLanes], deformation_gradient[4 * kLanes];
      alignas(64) double reference_volume[kLanes];
    } copy;
    auto lane_particles = [&](std::size_t first, int count) -> const GatherLaneParticles& {
      if (count == kLanes) {
        in_place = {values_of(P.position.data() + first), values_of(P.velocity.data() + first),
                    values_of(P.deformation_gradient.data() + first), P.reference_volume.data() + first};
        return in_place;
      }
      for (int l = 0; l < kLanes; ++l) {
        const std::size_t q = copied_lane_particle(first, count, l);
        std::copy_n(values_of(&P.position[q]), 2, copy.position + 2 * l);
        std::copy_n(values_of(&P.velocity[q]), 2, copy.velocity + 2 * l);
        std::copy_n(values_of(&P.deformation_gradient[q]), 4, copy.deformation_gradient + 4 * l);
        copy.reference_volume[l] = P.reference_volume[q];
      }
      in_place = {copy.position, copy.velocity, copy.deformation_gradient, copy.reference_volume};
      return in_place;
    };
    if constexpr (by_rows) {
      double* m = motion->data();
#pragma omp for schedule(static)
      for (std::size_t i = 0; i < g.mass.size(); ++i) {
        m[4 * i] = g.acceleration[i].x();
        m[4 * i + 1] = g.acceleration[i].y();
        m[4 * i + 2] = g.velocity[i].x();
        m[4 * i + 3] = g.velocity[i].y();
      }
    }
    // `entries(f)` passes each entry of the particle's stencil to f.
    // Inlined where it is visited: left out of line once the lanes' path
    // grew the stage, a stretched CPDI batch's update cost 365 instructions a
    // particle-step in the call alone (callgrind, A = 1, t = 0.40-0.44 s).
    auto update = [&](std::size_t p, auto&& entries) __attribute__((always_inline)) {
      Vec2 acceleration = Vec2::Zero(), velocity = Vec2::Zero();
      Mat2 L = Mat2::Zero();  // the velocity gradient, for F and for APIC's C_p
      double hoop_rate = 0.0;
      bool summed = false;
      if constexpr (by_rows && with_affine && requires { entries.lane; }) {
        // APIC's sums by lanes, in a batch whose every particle goes by rows
        // (the batch's hook gathered them); the update entry by entry.
        if (batch_by_rows) {
          const int l = entries.lane;
          acceleration = Vec2(lane_sums.acceleration[0][l], lane_sums.acceleration[1][l]);
          velocity = Vec2(lane_sums.velocity[0][l], lane_sums.velocity[1][l]);
          L << lane_sums.velocity_gradient[0][l], lane_sums.velocity_gradient[2][l],
              lane_sums.velocity_gradient[1][l], lane_sums.velocity_gradient[3][l];
          summed = true;
        }
      }
      if (!summed)
        entries([&](int i, double w, const Vec2& gradient, const double& hoop = 0.0) {
          if constexpr (with_velocity && !with_affine) acceleration += w * g.acceleration[i];
          if constexpr (with_position || with_affine) velocity += w * g.velocity[i];
          if constexpr (with_deformation || with_affine) L += g.velocity[i] * gradient.transpose();
          if constexpr (with_deformation && axisymmetric) hoop_rate += hoop * g.velocity[i].x();
        });
      if constexpr (with_deformation) {
        P.deformation_gradient[p] = (Mat2::Identity() + dt * L) * P.deformation_gradient[p];
        double J = determinant(P.deformation_gradient[p]);
        if constexpr (axisymmetric) {
          P.hoop_stretch[p] *= 1.0 + dt * hoop_rate;
          J *= P.hoop_stretch[p];
        }
        P.volume[p] = J * P.reference_volume[p];
      }
      if constexpr (with_affine) {
        P.velocity[p] = velocity;
        P.affine_velocity[p] = L;
      } else if constexpr (with_velocity) {
        P.velocity[p] += kick * acceleration;
      }
      if constexpr (with_position) position_out[p] = P.position[p] + dt * velocity;
    };
    // A batch whose every lane goes by rows (a CPDI domain stretched past a
    // cell by its corners' blocks) is updated by lanes whole (no affine
    // field), without a visit of each of its particles; a batch with a
    // stencil off the grid goes entry by entry whole.
    auto whole_batch = [&](std::size_t first, int count, const double*, auto&& batch) {
      if constexpr (by_rows) {
        batch_by_rows = false;
        if (!lane_blocks(shape, batch, lane_batch.first_node)) return false;  // entry by entry, the whole batch
        take_slots(batch, lane_batch);
        batch_by_rows = true;
        if constexpr (with_affine) {  // the sums by lanes, each particle then visited
          gather_lanes(GatherLaneGrid{motion->data(), row, nullptr, dt, kick}, lane_batch, lane_sums);
          return false;
        }
        GatherLaneGrid lane_grid{motion->data(), row, &lane_particles(first, count), dt, kick};
        if (count == kLanes) {
          // A batch in place: the kernel writes the update into the
          // particles' arrays itself (callgrind: the copy below cost 25-30
          // instructions a particle-step).
          if constexpr (with_deformation) {
            lane_grid.targets.deformation_gradient = values_of(&P.deformation_gradient[first]);
            lane_grid.targets.volume = &P.volume[first];
          }
          if constexpr (with_velocity) lane_grid.targets.velocity = values_of(&P.velocity[first]);
          if constexpr (with_position) lane_grid.targets.position = values_of(&position_out[first]);
          gather_lanes(lane_grid, lane_batch, lane_sums);
          return true;
        }
        gather_lanes(lane_grid, lane_batch, lane_sums);
        const GatherLaneSums& out = lane_sums;
        for (int l = 0; l < count; ++l) {
          const std::size_t p = first + std::size_t(l);
          if constexpr (with_deformation) {
            double* F = values_of(&P.deformation_gradient[p]);
            for (int k = 0; k < 4; ++k) F[k] = out.new_deformation_gradient[k][l];
            P.volume[p] = out.new_volume[l];
          }
          if constexpr (with_velocity) P.velocity[p] = Vec2(out.new_velocity[0][l], out.new_velocity[1][l]);
          if constexpr (with_position) position_out[p] = Vec2(out.new_position[0][l], out.new_position[1][l]);
        }
        return true;
      }
      return false;
    };
    for_each_stencil(
        shape, range.first, n, false, [](std::size_t, auto) { return true; },
        [&](std::size_t p, auto&& entries, auto&&, double) { update(p, entries); }, whole_batch);
  }
}

// ---------------------------------------------------------------- locking remedy

// Scales particle p's F to the dilatation J_target, F_p <- (J_target / J_p)^(1/d) F_p
// (eq. 1.84 with d = 2 for the in-plane block; in r-z the hoop stretch takes its
// share, d = 3), and sets V_p = J_target V_p0. The isochoric part of F is kept.
// A particle with no positive J is left to the health scan.
template <Geometry G>
void scale_to_dilatation(Particles& P, std::size_t p, double J_target) {
  const double J = P.volume[p] / P.reference_volume[p];
  if (!(J > 0.0 && J_target > 0.0)) return;
  if constexpr (G == Geometry::axisymmetric) {
    const double scale = std::cbrt(J_target / J);
    P.deformation_gradient[p] *= scale;
    P.hoop_stretch[p] *= scale;
  } else {
    P.deformation_gradient[p] *= std::sqrt(J_target / J);
  }
  P.volume[p] = J_target * P.reference_volume[p];
}

// The cell-averaged dilatation of 002_c3305cb8b1bc1490.txt eqs. 1.82-1.84: in
// each cell c (by the particles' centres), V_c0 = sum V_p0 and V_c = sum V_p
// give J_c = V_c / V_c0 (eqs. 1.82-1.83), and each particle's F is scaled to
// that dilatation, F_p <- (J_c / J_p)^(1/d) F_p (eq. 1.84 with d = 3; here
// d = 2 for the in-plane block, and in r-z the hoop stretch takes its share:
// d = 3 over (F_inplane, F_theta)), with V_p = J_c V_p0. It relaxes the
// volumetric constraint to one per cell, which is what unlocks a nearly
// incompressible material. `cell_volume` holds two sums per cell, per thread.
template <Geometry G>
void average_cell_dilatation(const GridGeometry& grid, Particles& P, std::vector<std::vector<double>>& cell_volume) {
  const std::size_t n = P.size();
  const std::size_t cells = std::size_t(grid.cells_x) * std::size_t(grid.cells_y);
  const int threads = int(cell_volume.size());
  auto cell_of = [&](std::size_t p) {
    const Vec2 xi = grid_coordinate(grid, P.position[p]);
    return std::size_t(cell_index(std::max(xi.y(), 0.0), grid.cells_y)) * std::size_t(grid.cells_x) +
           std::size_t(cell_index(std::max(xi.x(), 0.0), grid.cells_x));
  };
#pragma omp parallel num_threads(threads)
  {
    std::vector<double>& own = cell_volume[std::size_t(thread_id())];
    own.assign(2 * cells, 0.0);
#pragma omp for schedule(static)
    for (std::size_t p = 0; p < n; ++p) {
      const std::size_t c = cell_of(p);
      own[2 * c] += P.reference_volume[p];
      own[2 * c + 1] += P.volume[p];
    }
    sum_into_first(cell_volume, 2 * cells);
#pragma omp for schedule(static)
    for (std::size_t p = 0; p < n; ++p) {
      const std::size_t c = cell_of(p);
      const double J_cell = cell_volume[0][2 * c + 1] / cell_volume[0][2 * c];
      scale_to_dilatation<G>(P, p, J_cell);
    }
  }
}

// The same remedy with the grid's nodes in place of cells and the method's
// own weights in place of "the cell holding the centre": each node takes
// J_g = sum_p S_gp V_p / sum_p S_gp V_p0 (eqs. 1.82-1.83 with S_gp as the
// share of a particle a node holds), each particle reads back
// Jbar_p = sum_g S_gp J_g and is scaled to it as in eq. 1.84. A dilatation
// that varies from particle to particle within a node's reach, which the
// grid cannot push back on, is smoothed away; one the grid resolves is kept
// to second order. `node_volume` holds two sums per node, per thread.
template <class Shape>
void smooth_node_dilatation(const Shape& shape, Particles& P, std::vector<std::vector<double>>& node_volume,
                            std::size_t nodes) {
  constexpr Geometry G = Shape::geometry;
  const std::size_t n = P.size();
  const int threads = int(node_volume.size());
#pragma omp parallel num_threads(threads)
  {
    std::vector<double>& own = node_volume[std::size_t(thread_id())];
    own.assign(2 * nodes, 0.0);
    Stencil<Shape::stencil_size> s;
#pragma omp for schedule(static)
    for (std::size_t p = 0; p < n; ++p) {
      shape.evaluate(p, s);
      for (int k = 0; k < s.count; ++k) {
        own[2 * std::size_t(s.node[k])] += s.weight[k] * P.reference_volume[p];
        own[2 * std::size_t(s.node[k]) + 1] += s.weight[k] * P.volume[p];
      }
    }
    sum_into_first(node_volume, 2 * nodes);
    const std::vector<double>& sums = node_volume[0];
#pragma omp for schedule(static)
    for (std::size_t p = 0; p < n; ++p) {
      shape.evaluate(p, s);
      double J_bar = 0.0, weight = 0.0;
      for (int k = 0; k < s.count; ++k) {
        const std::size_t i = std::size_t(s.node[k]);
        if (!(sums[2 * i] > 0.0)) continue;
        J_bar += s.weight[k] * sums[2 * i + 1] / sums[2 * i];
        weight += s.weight[k];
      }
      J_bar /= weight;
      scale_to_dilatation<G>(P, p, J_bar);
    }
  }
}

// ---------------------------------------------------------------- constitutive update

// Particles [begin, end) of the material (a run with two materials calls it
// once for each, SceneStages::second_material); by default every particle.
inline constexpr std::size_t kAllParticles = std::size_t(-1);

template <Geometry G, class Material>
void update_stress(const Material& material, Particles& P, std::size_t begin = 0, std::size_t end = kAllParticles) {
  const std::size_t n = std::min(end, P.size());
  if constexpr (G == Geometry::axisymmetric) {
#pragma omp parallel for schedule(static)
    for (std::size_t p = begin; p < n; ++p) {
      const Stress<double> sigma = material.stress(P.deformation_gradient[p], P.hoop_stretch[p]);
      P.stress[p] = sigma.in_plane;
      P.hoop_stress[p] = sigma.out_of_plane;
    }
  } else if constexpr (requires { material.cauchy_stress_array(n, P.deformation_gradient.data(), P.stress.data()); }) {
    // A material that forms its stresses by lanes takes each thread's block at once.
#pragma omp parallel
    {
      const auto [first, last] = static_block(begin, n);
      if (last > first) material.cauchy_stress_array(last - first, &P.deformation_gradient[first], &P.stress[first]);
    }
  } else {
#pragma omp parallel for schedule(static)
    for (std::size_t p = begin; p < n; ++p) P.stress[p] = material.cauchy_stress(P.deformation_gradient[p]);
  }
}

// ---------------------------------------------------------------- bulk viscosity

// The artificial bulk viscosity of 002_c3305cb8b1bc1490.txt eqs. 1.66-1.67,
// sigma_p <- sigma_p - q_p I, with
//   q_p = -rho_p l_p (C0 c_p + C1 l_p |tr d_p|) tr d_p,
// c_p = sqrt(M / rho_p) the p-wave speed (eq. 1.66 writes sqrt(K / rho); the
// coefficient takes up the ratio) and tr d_p the particle's rate of
// dilatation over the step, ln(V_p / V_p_before) / dt. Eq. 1.66 puts |tr d| in
// the linear term, which would make q a pressure in expansion too; here q
// takes the sign of -tr d, so the stress power -q tr d V_p =
// rho l (C0 c + C1 l |tr d|) (tr d)^2 V_p is never negative: it dissipates in
// compression and expansion alike. A motion that keeps volume (the ring's,
// J = 1) feels it only through the dilatation the method gets wrong. In r-z
// the hoop stress takes the same -q.
// The length l_p is the particle's own thinnest width, the area of the
// method's domain (shape.domain, as the monitors read it) over its longest
// side (at most the cell size h; h for a method without one, linear and
// B-spline MPM). Eq. 1.66 suggests h; but a viscous stress is stable only to a
// step that shrinks with the square of the width its gradients act across,
// and a sheared CPDI domain grows thin: with l = h the ring at A = 1 on 256
// cells, which completes without viscosity, stopped with nan at t = 0.315 s
// (C0 = 0.2) and 0.398 s (C0 = 0.05).
struct ViscousStep {
  double dissipated = 0.0;  // sum_p -q_p tr d_p V_p dt >= 0 [J per unit depth]
  double max_ratio = 0.0;   // max_p C0 + C1 l_p |tr d_p| / c_p, the damping ratio xi of the fastest mode
};

template <class Shape>
ViscousStep add_bulk_viscosity(const Shape& shape, Particles& P, const std::vector<double>& volume_before,
                               double wave_modulus, double h, double c0, double c1, double dt, std::size_t begin = 0,
                               std::size_t end = kAllParticles) {
  constexpr Geometry G = Shape::geometry;
  constexpr bool has_domain = Shape::has_domain;
  const std::size_t n = std::min(end, P.size());
  double max_ratio = 0.0;
  ThreadOrderedSums<1> dissipated;
#pragma omp parallel
  {
    double own = 0.0;
#pragma omp for schedule(static) reduction(max : max_ratio)
    for (std::size_t p = begin; p < n; ++p) {
      const double rate = std::log(P.volume[p] / volume_before[p]) / dt;
      if (!std::isfinite(rate)) continue;  // the health scan reports the particle
      double l = h;
      if constexpr (has_domain) {  // the method's domain, half-vectors r1, r2: area over longest side
        const Mat2 s = shape.domain(p);
        l = std::min(h, 2.0 * std::abs(determinant(s)) / std::max(s.col(0).norm(), s.col(1).norm()));
      }
      const double density = P.mass[p] / P.volume[p];
      const double c = std::sqrt(wave_modulus / density);
      const double q = -density * l * (c0 * c + c1 * l * std::abs(rate)) * rate;
      P.stress[p](0, 0) -= q;
      P.stress[p](1, 1) -= q;
      if constexpr (G == Geometry::axisymmetric) P.hoop_stress[p] -= q;
      own += -q * rate * P.volume[p] * dt;
      max_ratio = std::max(max_ratio, c0 + c1 * l * std::abs(rate) / c);
    }
    dissipated.keep({own});
  }
  return {dissipated.total()[0], max_ratio};
}

// ---------------------------------------------------------------- tracers

// Massless probe points move with the grid velocity, interpolated with the
// bilinear hat and weighted by nodal mass, v = sum S m v / sum S m: they sample
// the motion the method computes without changing it, and at a free surface
// the nodes beyond the body, which carry only a sliver of mass and whatever
// velocity that sliver gives them, do not drag a tracer on the surface along.
// A tracer that leaves the grid, or finds no mass around it, becomes NaN.
//
// Under the total Lagrangian formulation the grid is the reference
// configuration: `reference` then holds each tracer's reference position,
// where the grid is read, while `tracers` holds where it is now.
inline void advect_tracers(const GridGeometry& grid, const GridFields& g, std::vector<Vec2>& tracers,
                           double dt, const std::vector<Vec2>* reference = nullptr) {
  for (std::size_t t = 0; t < tracers.size(); ++t) {
    Vec2& x = tracers[t];
    const Vec2& at = reference ? (*reference)[t] : x;
    if (!inside_cells(grid, grid_coordinate(grid, at)) || !x.allFinite()) {
      x.setConstant(std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    int node[4];
    double w[4];
    bilinear_cell_weights(grid, at, node, w);
    Vec2 momentum = Vec2::Zero();
    double mass = 0.0;
    for (int k = 0; k < 4; ++k) {
      momentum += w[k] * g.mass[node[k]] * g.velocity[node[k]];
      mass += w[k] * g.mass[node[k]];
    }
    if (mass > 0.0) {
      x += dt * momentum / mass;
    } else {
      x.setConstant(std::numeric_limits<double>::quiet_NaN());
    }
  }
}

// ---------------------------------------------------------------- health and time step

struct ParticleScan {
  double max_signal_speed = 0.0;  // max_p (max(c_p, k_p c0_p) + |v_p|): scan_particles
  std::size_t first_unhealthy;    // lowest index of a particle that stops the run, or size()
};

// Out-of-plane stretch of particle p: F_theta in r-z, 1 in plane strain.
template <Geometry G>
double out_of_plane_stretch(const Particles& P, std::size_t p) {
  if constexpr (G == Geometry::axisymmetric) return P.hoop_stretch[p];
  return 1.0;
}

// `inside`, if given, returns shape.inside(p) (a caller that has it cheaper
// passes its own); it is asked only of a particle whose state is finite and
// unfolded, as before.
template <class Shape, class Inside = std::nullptr_t>
bool particle_healthy(const Shape& shape, const Particles& P, std::size_t p, Inside inside = nullptr) {
  const double F33 = out_of_plane_stretch<Shape::geometry>(P, p);
  const double J = determinant(P.deformation_gradient[p]) * F33;
  // 0 x is +-0 for a finite x and NaN for an infinite or NaN one: the sum of
  // the products is zero exactly when every entry is finite, with no branch
  // per entry (the test runs for every particle every step). Summed as a
  // tree of pairs, not a chain: twelve additions in a row each wait for the
  // last.
  const Mat2& F = P.deformation_gradient[p];
  const Mat2& stress = P.stress[p];
  const Vec2 pairs = (0.0 * P.position[p] + 0.0 * P.velocity[p]) +
                     ((0.0 * F.col(0) + 0.0 * stress.col(0)) + (0.0 * F.col(1) + 0.0 * stress.col(1)));
  double zero = pairs.x() + pairs.y();
  if constexpr (Shape::geometry == Geometry::axisymmetric) zero += 0.0 * P.hoop_stress[p];
  if (!(zero == 0.0 && J > 0.0)) return false;
  if constexpr (std::is_same_v<Inside, std::nullptr_t>) return shape.inside(p);
  else return inside();
}

// The sum over nodes of |G_gp| of a stencil, each node counted once: a full
// stencil may list a node more than once (a stretched CPDI domain, once per
// corner that reaches it); one that is not full (cpdi.hpp) lists each node
// once already.
template <int N>
double entry_gradient_sum(const Stencil<N>& s);

template <int N>
double gradient_sum(const Stencil<N>& s) {
  if (s.count < N) return entry_gradient_sum(s);
  // The nodes merged (merged_gradients); then the lengths, computed apart
  // from the sum so that their square roots do not wait on one another.
  int node[N];
  Vec2 g[N];
  const int nodes = merged_gradients(s, node, g, [](int) { return false; });
  double length[N];
  for (int j = 0; j < nodes; ++j) length[j] = g[j].norm();
  double sum = 0.0;
  for (int j = 0; j < nodes; ++j) sum += length[j];
  return sum;
}

// The sum of |G_gp| over a stencil's entries as listed: at least the sum over
// nodes above (the triangle inequality), and equal to it, in the same order
// of additions, where no node repeats.
template <int N>
double entry_gradient_sum(const Stencil<N>& s) {
  double sum = 0.0;
  for (int k = 0; k < s.count; ++k) sum += s.gradient[k].norm();
  return sum;
}

// The same for particle p's stencil, evaluated here.
template <class Shape>
double gradient_sum(const Shape& shape, std::size_t p) {
  Stencil<Shape::stencil_size> s;
  shape.evaluate(p, s);
  return gradient_sum(s);
}

// How many times higher particle p lifts the grid's frequencies than the
// grid's own basis can: 1, or h sum_g |G_gp| / (2 + sqrt 2) where that is
// larger. The bilinear basis's gradients sum over the four nodes of a point
// to at most (2 + sqrt 2) / h (at a node: sqrt 2 + 1 + 1 + 0), and the step
// cfl h / (c + |v|) is set for them; any average of them over a domain (GIMP,
// exact CPDI) stays within that. CPDI interpolates the basis bilinearly
// between its domain's corners (002_c3305cb8b1bc1490.txt eq. 1.95); where a
// sheared domain's corners straddle cell lines the interpolant is not the
// basis, and its gradient, s_p^-T times differences of S_g between corners,
// grows as 1 / sin of the angle between r_1 and r_2. A particle's stiffness
// grows with the square of its gradients while its mass stays, so the
// frequencies it takes part in grow with them.
inline constexpr double kGridBasisGradientBound = 2.0 + 1.4142135623730951;  // times 1 / h

template <class Shape>
double stiffening(const Shape& shape, std::size_t p, double h) {
  if constexpr (Shape::gradients_beyond_grid_basis) {
    return std::max(1.0, h * gradient_sum(shape, p) / kGridBasisGradientBound);
  } else {
    return 1.0;
  }
}

// The same from the particle's stencil, where the caller has it.
template <int N>
double stiffening(const Stencil<N>& s, double h) {
  return std::max(1.0, h * gradient_sum(s) / kGridBasisGradientBound);
}

// The largest signal speed max(c_p, k_p c0_p) + |v_p| over particles (c_p +
// |v_p| where k_p = 1) and the first particle whose state stops the run. c_p is the material's
// wave speed bound at the particle's current state (it grows with the stress
// along a stretched direction), c0_p the small-strain wave speed
// sqrt((lambda + 2 mu) / rho_p), k_p the particle's stiffening (above), and
// rho_p = m_p / V_p. The corner interpolation's large gradients run across a
// sheared domain's thin width, the stress that stiffens the material along
// its stretched length, so the two lift the largest frequency each on its
// own, not as a product: on the ring at A = 1 (CPDI, 256 cells) the measured
// omega_max (Stepper::largest_frequency) grows 6.6 times by t = 0.5 s, k_p
// to 8.0, c_p / c0_p to about 4. Without k_p the step outgrows 2 / omega_max
// as the ring comes to rest most twisted, and finer meshes, taking more steps
// through that stretch, blow up first.
//
// Particle p's term, given the largest so far: k_p needs the particle's
// stencil, which is costly, and merging its repeated nodes, so it is formed
// only where the particle could set a new largest speed (the bounds below are
// exact-safe: the maximum is what forming every k_p gives). `stencil_of()`
// gives the particle's stencil where the caller has it at the same state
// (ScanInMap; asked for only where the bounds do not settle k_p), else null.
//
// Most particles cannot set a new largest: a bound of their speed without the
// material's logarithm and square roots (its wave_modulus_bound) rules them
// out first. The margin of 1e-9 covers the round-off of the exact terms, so a
// particle left out is one whose speed could not have changed the maximum.
template <class Shape, class Material, class StencilOf = std::nullptr_t>
double signal_speed(const Shape& shape, const Material& material, const Particles& P, double h, std::size_t p,
                    double largest, StencilOf stencil_of = nullptr, double stencil_gradient_bound = -1.0) {
  constexpr bool with_stencil = !std::is_null_pointer_v<StencilOf>;
  const double density = P.mass[p] / P.volume[p];
  const double F33 = out_of_plane_stretch<Shape::geometry>(P, p);
  const double v = P.velocity[p].norm();
  // With the stencil at hand the bound of k_p is its sum of |G| over entries,
  // which is k_p's own sum where no node repeats (a stencil that is not full);
  // the test that rules a particle out reads a bound of that sum without
  // square roots (entry_gradient_sum_bound, or the caller's
  // `stencil_gradient_bound` of the same stencil) and the sum itself only if
  // it has to.
  [[maybe_unused]] double most = 1.0;
  [[maybe_unused]] bool most_exact = true;
  if constexpr (Shape::gradients_beyond_grid_basis) {
    if constexpr (with_stencil) {
      const double bound =
          stencil_gradient_bound >= 0.0 ? stencil_gradient_bound : entry_gradient_sum_bound(stencil_of());
      // h bound / (2 + sqrt 2), lifted past what its rounding could take off:
      // where it is 1, k_p's own bound, no larger, is 1 too.
      constexpr double inverse = 1.0 / kGridBasisGradientBound;
      most = std::max(1.0, h * bound * inverse * (1.0 + 1e-12));
      most_exact = most == 1.0;
    } else {
      most = std::max(1.0, h * shape.gradient_sum_bound(p) / kGridBasisGradientBound);
    }
  }
  if constexpr (!requires { shape.cell_stretch(p); } &&
                requires { material.wave_modulus_bound(P.deformation_gradient[p], F33, P.stress[p]); }) {
    const double room = largest * (1.0 - 1e-9) - v;
    if (room > 0.0) {
      double modulus = material.wave_modulus_bound(P.deformation_gradient[p], F33, P.stress[p]);
      if constexpr (Shape::gradients_beyond_grid_basis)
        modulus = std::max(modulus, most * most * material.p_wave_modulus());
      if (modulus <= density * room * room) return 0.0;
    }
  }
  // Past the test, with the stencil at hand, k_p itself: the sum over
  // entries where no node repeats, else the sum over nodes (stiffening).
  // Either is at most the bound above, so a particle the next test leaves
  // out could not have set the maximum with it.
  if constexpr (Shape::gradients_beyond_grid_basis && with_stencil) {
    if (!most_exact) {
      const auto& stencil = stencil_of();
      most = stencil.count == Shape::stencil_size
                 ? stiffening(stencil, h)
                 : std::max(1.0, h * entry_gradient_sum(stencil) / kGridBasisGradientBound);
    }
  }
  const double c = std::sqrt(material.wave_modulus(P.deformation_gradient[p], F33, P.stress[p]) / density);
  double speed = c;
  // The total Lagrangian formulation: a wave crosses the current image of a
  // reference cell, F_p h along its most compressed direction.
  if constexpr (requires { shape.cell_stretch(p); }) speed = c / std::min(1.0, shape.cell_stretch(p));
  if constexpr (Shape::gradients_beyond_grid_basis) {
    const double c_small = std::sqrt(material.p_wave_modulus() / density);
    if (std::max(c, most * c_small) + v > largest) {
      double k = most;
      if constexpr (!with_stencil) k = stiffening(shape, p, h);
      if (k > 1.0) speed = std::max(c, k * c_small);
    }
  }
  return speed + v;
}

// One pass over particles [begin, end) of one material; first_unhealthy is
// P.size() when none of them stops the run.
template <class Shape, class Material>
ParticleScan scan_particles(const Shape& shape, const Material& material, const Particles& P, double h,
                            std::size_t begin = 0, std::size_t end = kAllParticles) {
  const std::size_t n = std::min(end, P.size());
  double max_speed = 0.0;
  std::size_t first = P.size();
#pragma omp parallel for schedule(static) reduction(max : max_speed) reduction(min : first)
  for (std::size_t p = begin; p < n; ++p) {
    if (!particle_healthy(shape, P, p)) {
      first = std::min(first, p);
      continue;
    }
    max_speed = std::max(max_speed, signal_speed(shape, material, P, h, p, max_speed));
  }
  return {max_speed, first};
}

// The screen's view of particles first, ..., first + count - 1 (count at
// most kLanes) with their stencils' bounds (the shape's lane_gradient_bounds,
// null where it has none: the screen reads them only for a shape that
// stiffens): P's own arrays where the batch is whole, else `copy` with the
// spare lanes repeating the first.
inline NeoHookeanScanLaneInput scan_lane_input(const Particles& P, std::size_t first, int count,
                                               const double* gradient_bound, NeoHookeanScanLaneCopy& copy) {
  if (count == kLanes)
    return {values_of(&P.position[first]),
            values_of(&P.velocity[first]),
            values_of(&P.deformation_gradient[first]),
            values_of(&P.stress[first]),
            P.mass.data() + first,
            P.volume.data() + first,
            gradient_bound};
  for (int l = 0; l < kLanes; ++l) {
    const std::size_t p = copied_lane_particle(first, count, l);
    std::copy_n(values_of(&P.position[p]), 2, copy.position + 2 * l);
    std::copy_n(values_of(&P.velocity[p]), 2, copy.velocity + 2 * l);
    std::copy_n(values_of(&P.deformation_gradient[p]), 4, copy.deformation_gradient + 4 * l);
    std::copy_n(values_of(&P.stress[p]), 4, copy.stress + 4 * l);
    copy.mass[l] = P.mass[p];
    copy.volume[l] = P.volume[p];
  }
  return {copy.position, copy.velocity, copy.deformation_gradient, copy.stress, copy.mass, copy.volume, gradient_bound};
}

// The same scan made by the map of the step to come (particles_to_grid), which
// weighs the state the scan reads and evaluates every particle's stencil
// anyway: the map tests a particle's health before it evaluates the stencil
// (an unhealthy particle's stencil may leave the grid) and skips one that
// fails; then the speed reads the stencil the map has. One material.
template <class Shape, class Material>
struct ScanInMap {
  const Shape& shape;
  const Material& material;
  const Particles& P;
  double h;
  ParticleScan result{0.0, P.size()};

  // Where the material has a lane kernel of the scan's first tests
  // (neo_hookean_lanes.hpp), in plane strain, the batch's particles are
  // screened together into `screen`: the scan then asks each only of what
  // the screen left open. A shape whose gradients reach beyond the grid
  // basis needs the lane kernel's bounds of its stencils for that, so it is
  // screened only where it evaluates by lanes. Otherwise the screen stays
  // empty.
  static constexpr bool screens = std::is_same_v<Material, NeoHookean> &&
                                  (evaluates_lanes<Shape>() || !Shape::gradients_beyond_grid_basis) &&
                                  Shape::geometry == Geometry::plane_strain &&
                                  !requires(const Shape& s) { s.cell_stretch(std::size_t(0)); };

  void screen_lanes(std::size_t first, int count, const double* gradient_bounds, double largest,
                    ScanScreen& screen) const {
    if constexpr (screens) {
      const NeoHookeanScanLaneParams params{material.lambda, material.mu, material.p_wave_modulus(), largest, h,
                                            1.0 / kGridBasisGradientBound, Shape::gradients_beyond_grid_basis};
      NeoHookeanScanLaneCopy copy;
      const NeoHookeanScanLaneInput in = scan_lane_input(P, first, count, gradient_bounds, copy);
      neo_hookean_scan_lanes(params, in, screen.verdict);
      screen.first = first;
      screen.valid = true;
    }
  }

  template <class Inside>
  bool healthy(std::size_t p, Inside inside, const ScanScreen& screen = {}) const {
    if constexpr (screens) {
      if (screen.valid) return screen.verdict.sound[p - screen.first] != 0 && inside();
    }
    return particle_healthy(shape, P, p, inside);
  }
  // `stencil_of()` gives the particle's stencil; `gradient_bound` is its
  // entry_gradient_sum_bound where the caller has it, else negative.
  template <class StencilOf>
  double speed(std::size_t p, StencilOf stencil_of, double largest, double gradient_bound = -1.0,
               const ScanScreen& screen = {}) const {
    if constexpr (screens) {
      if (screen.valid && screen.verdict.may_set_speed[p - screen.first] == 0) return 0.0;
    }
    return signal_speed(shape, material, P, h, p, largest, stencil_of, gradient_bound);
  }
};

// The scan of a run with two materials: the larger speed, the first particle.
inline ParticleScan combined(const ParticleScan& a, const ParticleScan& b) {
  return {std::max(a.max_signal_speed, b.max_signal_speed), std::min(a.first_unhealthy, b.first_unhealthy)};
}

}  // namespace mpmvv
