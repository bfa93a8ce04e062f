// What the tests share: deformation gradients, number formatting and the
// builds of the lane kernels this CPU can run.
#pragma once

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "solver/lanes.hpp"
#include "solver/tensor.hpp"

namespace mpmvv::testing {

// x in scientific notation with `digits` after the point, for test properties.
inline std::string scientific(double x, int digits = 3) {
  char text[40];
  std::snprintf(text, sizeof text, "%.*e", digits, x);
  return text;
}

inline Mat2 rotation(double angle) {
  Mat2 q;
  q << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  return q;
}

// x = X + gamma Y e_x.
inline Mat2 simple_shear(double gamma) {
  Mat2 f;
  f << 1.0, gamma, 0.0, 1.0;
  return f;
}

// Random F = I + perturbation, entries uniform in [-spread, spread], redrawn
// until det F >= min_det.
template <class Rng>
Mat2 random_deformation(Rng& rng, double spread, double min_det) {
  std::uniform_real_distribution<double> u(-spread, spread);
  for (;;) {
    Mat2 f = Mat2::Identity();
    f(0, 0) += u(rng);
    f(0, 1) += u(rng);
    f(1, 0) += u(rng);
    f(1, 1) += u(rng);
    if (determinant(f) >= min_det) return f;
  }
}

// Every build of the lane kernels (solver/lanes.hpp) the CPU has, baseline first.
inline std::vector<LaneBuild> lane_builds_of_this_cpu() {
  std::vector<LaneBuild> builds;
  for (LaneBuild b : {LaneBuild::baseline, LaneBuild::avx2, LaneBuild::avx512})
    if (cpu_has(b)) builds.push_back(b);
  return builds;
}

}  // namespace mpmvv::testing
