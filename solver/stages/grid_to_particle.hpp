// Grid to particle: velocity, position, F and volume back from the nodes (eqs.
// 1.72-1.76, 1.97). A stage of solver/stages.hpp.
#pragma once

#include "grid_update.hpp"

namespace mpmvv {

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

}  // namespace mpmvv
