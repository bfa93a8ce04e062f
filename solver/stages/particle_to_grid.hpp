// Particle to grid: the mass, momentum and forces each particle gives the
// nodes (eqs. 1.69-1.70), by stencils or by lanes of eight, with the time-step
// scan folded into the map. A stage of solver/stages.hpp.
#pragma once

#include "scatter.hpp"

namespace mpmvv {

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

}  // namespace mpmvv
