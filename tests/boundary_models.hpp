// What the boundary and exact-scene tests share (test_boundary.cpp,
// test_exact_scenes.cpp): a block of particles on a walled grid, its solid and
// its kinetic energy.
#pragma once

#include <vector>

#include "solver/boundary.hpp"
#include "solver/explicit_stepper.hpp"

namespace mpmvv::testing::boundary_models {

using mpmvv::GridFields;
using mpmvv::GridGeometry;
using mpmvv::Mat2;
using mpmvv::Method;
using mpmvv::Model;
using mpmvv::NodeConstraint;
using mpmvv::Particles;
using mpmvv::SceneStages;
using mpmvv::Scheme;
using mpmvv::SolverOptions;
using mpmvv::Vec2;

// A square block of particles, 2 per cell per direction, at rest, away from
// the walls of a 16 x 16 grid of unit cells.
inline Model block(Method method) {
  Model m;
  m.grid = GridGeometry::walled(Vec2::Zero(), 1.0, 16, 16);
  Particles& P = m.particles;
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) {
      const Vec2 X = Vec2(4.25 + 0.5 * i, 4.25 + 0.5 * j);
      P.reference_position.push_back(X);
    }
  const std::size_t n = P.reference_position.size();
  std::vector<Vec2> X = P.reference_position;
  P.resize(n);
  P.reference_position = X;
  P.position = X;
  for (std::size_t p = 0; p < n; ++p) {
    P.reference_volume[p] = P.volume[p] = 0.25;
    P.mass[p] = 1000.0 * 0.25;
  }
  if (method != Method::linear) P.half_size.assign(n, Vec2(0.25, 0.25));
  return m;
}

inline const mpmvv::LinearElastic kSolid{2.0e6, 1.0e6};

inline double kinetic_energy(const Particles& P) {
  double e = 0.0;
  for (std::size_t p = 0; p < P.size(); ++p) e += 0.5 * P.mass[p] * P.velocity[p].squaredNorm();
  return e;
}


}  // namespace mpmvv::testing::boundary_models
