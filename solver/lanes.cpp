#include "lanes.hpp"

#include <cstdlib>
#include <cstring>
#include <initializer_list>

namespace mpmvv {

bool cpu_has(LaneBuild build) {
#if defined(MPMVV_LANES_X86)
  __builtin_cpu_init();
  switch (build) {
    // Without DQ and VL a comparison's mask would reach a vector lane by lane.
    case LaneBuild::avx512:
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
             __builtin_cpu_supports("avx512vl");
    case LaneBuild::avx2: return __builtin_cpu_supports("avx2");
    case LaneBuild::baseline: return true;
  }
  return false;
#else
  return build == LaneBuild::baseline;
#endif
}

LaneBuild widest_lane_build() {
  if (const char* chosen = std::getenv("MPMVV_LANE_BUILD")) {
    for (LaneBuild b : {LaneBuild::avx512, LaneBuild::avx2, LaneBuild::baseline})
      if (std::strcmp(chosen, name(b)) == 0 && cpu_has(b)) return b;
  }
  for (LaneBuild b : {LaneBuild::avx512, LaneBuild::avx2})
    if (cpu_has(b)) return b;
  return LaneBuild::baseline;
}

LaneBuild lane_build() {
  static const LaneBuild build = widest_lane_build();
  return build;
}

const char* name(LaneBuild build) {
  switch (build) {
    case LaneBuild::avx512: return "avx512";
    case LaneBuild::avx2: return "avx2";
    case LaneBuild::baseline: return "baseline";
  }
  return "?";
}

}  // namespace mpmvv
