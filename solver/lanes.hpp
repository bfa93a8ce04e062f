// Particle loops in lanes: a stencil kernel (shape/cpdi_lanes.hpp,
// shape/gimp_lanes.hpp) computes eight particles at once, each in a lane of
// one vector, and is compiled three times, for the baseline x86-64 (SSE2),
// for AVX2 and for AVX-512 (solver/CMakeLists.txt: each build its own
// compilation of the kernel, so that every vector operation is lowered for
// the instructions it runs on). The widest build the CPU has is chosen once,
// when it is first asked for; every build gives the same bits as the scalar
// code, since no build fuses a multiply with an add and each repeats the
// scalar code's operations in its order.
#pragma once

#include <cstddef>

namespace mpmvv {

inline constexpr int kLanes = 8;

// A lane's nodes for the transfers by rows (scatter_lanes.hpp,
// gather_lanes.hpp), as a shape's lane_block_first gives them: the first
// node of its block where they are one (3 x 3; linear's 2 x 2), else one of
// these.
inline constexpr int kNoBlock = -1;    // none: the lane goes entry by entry
inline constexpr int kByCorners = -2;  // CPDI's sixteen entries (a domain stretched past a cell): four
                                       // blocks of 2 x 2 nodes, one per corner's cell (corner_first)

// The particle lane l holds where a batch of `count` particles from `first`
// is copied into lanes (a batch of fewer than kLanes, or one that cannot be
// read in place): its own, and the first's in the spare lanes, so that they
// compute what the batch's own lanes do.
inline std::size_t copied_lane_particle(std::size_t first, int count, int l) {
  return first + std::size_t(l < count ? l : 0);
}

// A shape's batch of kLanes particles from `first` with its lane kernel's
// stencils (shape/cpdi.hpp, gimp.hpp, linear.hpp: compute_lanes).
template <class Stencils>
struct LaneBatchOfStencils {
  std::size_t first;
  Stencils out;
};

enum class LaneBuild { baseline, avx2, avx512 };  // avx512: its F, DQ and VL extensions

bool cpu_has(LaneBuild build);
// The widest build the CPU has, or the one the environment's
// MPMVV_LANE_BUILD names (avx512, avx2 or baseline) where the CPU has it:
// for benchmarks that compare the builds on one machine.
LaneBuild widest_lane_build();
// The build the kernels run: widest_lane_build(), chosen once.
LaneBuild lane_build();
const char* name(LaneBuild build);

}  // namespace mpmvv

// Declares a kernel function, inside namespace mpmvv, once in each build's
// namespace (solver/CMakeLists.txt compiles each kernel file once a build);
// the dispatch (lane_vectors.hpp: MPMVV_LANE_BUILD_CALL) picks one.
#define MPMVV_LANE_KERNEL(...)     \
  namespace lanes::avx512 {        \
  __VA_ARGS__;                     \
  }                                \
  namespace lanes::avx2 {          \
  __VA_ARGS__;                     \
  }                                \
  namespace lanes::baseline {      \
  __VA_ARGS__;                     \
  }
