#include "lanes.hpp"

#include <initializer_list>

namespace mpmvv {

bool cpu_has(LaneBuild build) {
#if defined(__x86_64__) && defined(__GNUC__)
  __builtin_cpu_init();
  switch (build) {
    case LaneBuild::avx512f: return __builtin_cpu_supports("avx512f");
    case LaneBuild::avx2: return __builtin_cpu_supports("avx2");
    case LaneBuild::baseline: return true;
  }
  return false;
#else
  return build == LaneBuild::baseline;
#endif
}

LaneBuild widest_lane_build() {
  for (LaneBuild b : {LaneBuild::avx512f, LaneBuild::avx2})
    if (cpu_has(b)) return b;
  return LaneBuild::baseline;
}

const char* name(LaneBuild build) {
  switch (build) {
    case LaneBuild::avx512f: return "avx512f";
    case LaneBuild::avx2: return "avx2";
    case LaneBuild::baseline: return "baseline";
  }
  return "?";
}

}  // namespace mpmvv
