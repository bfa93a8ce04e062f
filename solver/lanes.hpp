// Particle loops in lanes: a stencil kernel (shape/cpdi_lanes.hpp,
// shape/gimp_lanes.hpp) computes eight particles at once, each in a lane of
// one vector, and is compiled three times, for the baseline x86-64 (SSE2),
// for AVX2 and for AVX-512. The widest build the CPU has is chosen once, when
// the program starts; every build gives the same bits as the scalar code,
// since no build fuses a multiply with an add (solver/CMakeLists.txt) and
// each repeats the scalar code's operations in its order.
#pragma once

namespace mpmvv {

inline constexpr int kLanes = 8;

enum class LaneBuild { baseline, avx2, avx512f };

bool cpu_has(LaneBuild build);
LaneBuild widest_lane_build();
const char* name(LaneBuild build);

}  // namespace mpmvv
