// The time-step scan's first look at eight particles of a neo-Hookean solid
// at once, each in a lane (lanes.hpp), before the particle-to-grid map
// weighs them (stages.hpp: ScanInMap): whether each particle's state is
// finite with J > 0 (particle_healthy without its test of the domain in the
// grid), and whether its signal speed could set a new largest one
// (signal_speed's test by wave_modulus_bound, neo_hookean.hpp). A lane the
// test rules out is one the scalar test rules out too: the lanes repeat its
// operations in its order, with the largest speed as the batch found it,
// which is no larger than the scalar test's.
//
// Why: that test waits on a square root and two divisions per particle. On
// the CPDI ring (256 cells, one thread) a second scalar test per particle
// added 23 ns to a 135 ns particle-step; screened by lanes, the map with its
// scan went from 67-70 to 58-63 ns.
#pragma once

#include <cstddef>
#include <limits>

#include "../lanes.hpp"

namespace mpmvv {

struct NeoHookeanScanLaneParams {
  double lambda, mu;
  double p_wave_modulus;       // lambda + 2 mu
  double largest;              // the largest signal speed so far
  double h;                    // the cell size
  double inverse_basis_bound;  // 1 / kGridBasisGradientBound (stages.hpp)
  bool stiffens;               // the shape's gradients reach beyond the grid basis (k_p, stages.hpp)
};

// The particles of the eight lanes, each array holding them one after
// another as Particles does (its arrays read in place): x_p and v_p (two
// values a particle), F_p and sigma_p in plane strain (four, column by
// column), m_p, V_p, and the stencil's bound of sum_g |G_gp| (negative where
// there is none). NeoHookeanScanLaneCopy holds them for fewer particles.
struct NeoHookeanScanLaneInput {
  const double* position;
  const double* velocity;
  const double* deformation_gradient;
  const double* stress;
  const double* mass;
  const double* volume;
  const double* gradient_bound;
};

// The same values for a batch of fewer than eight particles, the spare lanes
// repeating the first (stages.hpp: scan_lane_input).
struct NeoHookeanScanLaneCopy {
  alignas(64) double position[2 * kLanes];
  alignas(64) double velocity[2 * kLanes];
  alignas(64) double deformation_gradient[4 * kLanes];
  alignas(64) double stress[4 * kLanes];
  alignas(64) double mass[kLanes];
  alignas(64) double volume[kLanes];
};

// Per lane: `sound`, nonzero where the state is finite and J > 0;
// `may_set_speed`, nonzero where the speed must be formed, i.e. the test
// could not rule the particle out (a stiffening shape without the stencil's
// bound, or a state that is not sound, is never ruled out).
struct NeoHookeanScanLaneVerdict {
  alignas(32) int sound[kLanes];
  alignas(32) int may_set_speed[kLanes];
};

// With the build the kernels run (lane_build), or with a given one, which
// the CPU must have (cpu_has).
void neo_hookean_scan_lanes(const NeoHookeanScanLaneParams& params, const NeoHookeanScanLaneInput& in,
                            NeoHookeanScanLaneVerdict& out);
void neo_hookean_scan_lanes(LaneBuild build, const NeoHookeanScanLaneParams& params,
                            const NeoHookeanScanLaneInput& in, NeoHookeanScanLaneVerdict& out);

// The stress update of n particles in plane strain, NeoHookean::cauchy_stress
// in lanes: F_p in, sigma_p out, four values a particle column by column as
// Particles holds them. Each lane repeats cauchy_stress's operations in its
// order, with ln J from the lanes (lane_log.hpp, within one unit in the last
// place), so a stress differs from the scalar one only through ln J's last
// place (tests/test_materials.cpp: within 1.6 epsilon of its terms' size).
// Returns how many particles have a J = det F_p that is not positive, finite
// and normal: their stresses are left for the caller to form
// (neo_hookean.hpp: cauchy_stress_array).
//
// Why: libm's log was 48 of the 111 instructions a particle-step of the
// scalar stress update on the ring (callgrind, 256 cells, CPDI and linear
// MPM alike), its latency on every particle's path.
struct NeoHookeanStressLaneParams {
  double lambda, mu;
};

// The J whose stress the lanes form: positive, finite and normal (lane_log's
// domain), between the smallest normal and the largest finite double. The
// kernel and the caller that forms the others' stresses test the same bounds.
inline constexpr double kLaneStressSmallestJ = 0x1p-1022;
inline constexpr double kLaneStressLargestJ = 0x1.fffffffffffffp+1023;
static_assert(kLaneStressSmallestJ == std::numeric_limits<double>::min() &&
              kLaneStressLargestJ == std::numeric_limits<double>::max());
inline bool lane_stress_takes(double J) { return J >= kLaneStressSmallestJ && J <= kLaneStressLargestJ; }

std::size_t neo_hookean_lane_stress(const NeoHookeanStressLaneParams& params, std::size_t n,
                                    const double* deformation_gradient, double* stress);
std::size_t neo_hookean_lane_stress(LaneBuild build, const NeoHookeanStressLaneParams& params, std::size_t n,
                                    const double* deformation_gradient, double* stress);

// Each build's own, compiled for its instructions (solver/CMakeLists.txt).
MPMVV_LANE_KERNEL(void neo_hookean_scan_lanes(const NeoHookeanScanLaneParams& params,
                                              const NeoHookeanScanLaneInput& in, NeoHookeanScanLaneVerdict& out))
MPMVV_LANE_KERNEL(void neo_hookean_stress_array(const NeoHookeanStressLaneParams& params, std::size_t n,
                                                const double* deformation_gradient, double* stress,
                                                std::size_t& outside))

}  // namespace mpmvv
