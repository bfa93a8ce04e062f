// What the solver tests share (test_solver.cpp, test_cpdi_domains.cpp,
// test_cpdi_corners.cpp, test_time_loop.cpp, test_stable_step.cpp,
// test_time_step_scan.cpp): the report's solid, a disk of particles on a small
// grid, stepping it, its momentum, and observers and options for short runs.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "solver/explicit_stepper.hpp"
#include "solver/time_loop.hpp"

namespace mpmvv::testing::solver_models {

using mpmvv::Mat2;
using mpmvv::MaterialModel;
using mpmvv::Method;
using mpmvv::Model;
using mpmvv::NeoHookean;
using mpmvv::Particles;
using mpmvv::Scheme;
using mpmvv::SolverOptions;
using mpmvv::Stepper;
using mpmvv::Vec2;

// The report's neo-Hookean solid (000_1dbcb8acb6dddab9.txt eq. 2.2).
inline const NeoHookean kSolid{577.0, 385.0};
inline constexpr double kDensity = 1000.0;  // rho_0 [kg/m^3]

inline const Method kMethods[] = {Method::linear, Method::gimp, Method::cpdi, Method::cpdi_exact};
inline const Scheme kSchemes[] = {Scheme::usl, Scheme::usf, Scheme::musl};

inline std::string label(Method m, Scheme s) { return std::string(to_string(m)) + "/" + to_string(s); }

// A disk of radius 0.8 m centred on a square domain [-2, 2]^2 of `cells`
// cells per side, seeded on a lattice of two particles per cell per
// direction, at rest and unstressed.
inline Model disk_model(Method method, int cells = 32) {
  Model model;
  model.grid.origin = Vec2(-2.0, -2.0);
  model.grid.cells_x = model.grid.cells_y = cells;
  model.grid.h = 4.0 / cells;
  const double spacing = 0.5 * model.grid.h;
  const double reference_volume = spacing * spacing;
  std::vector<Vec2> lattice;
  for (int j = 0; j < 2 * cells; ++j)
    for (int i = 0; i < 2 * cells; ++i) {
      const Vec2 x = model.grid.origin + spacing * Vec2(i + 0.5, j + 0.5);
      if (x.norm() < 0.8) lattice.push_back(x);
    }
  Particles& P = model.particles;
  P.resize(lattice.size());
  for (std::size_t p = 0; p < lattice.size(); ++p) {
    P.position[p] = P.reference_position[p] = lattice[p];
    P.mass[p] = kDensity * reference_volume;
    P.volume[p] = P.reference_volume[p] = reference_volume;
  }
  if (method != Method::linear) P.half_size.assign(lattice.size(), Vec2(0.5 * spacing, 0.5 * spacing));
  return model;
}

// One more particle at x, like the disk's, appended to the model.
inline void add_particle(Model& model, Method method, const Vec2& x) {
  Particles& P = model.particles;
  const double spacing = 0.5 * model.grid.h;
  P.position.push_back(x);
  P.reference_position.push_back(x);
  P.velocity.push_back(Vec2::Zero());
  P.deformation_gradient.push_back(Mat2::Identity());
  P.stress.push_back(Mat2::Zero());
  P.mass.push_back(kDensity * spacing * spacing);
  P.volume.push_back(spacing * spacing);
  P.reference_volume.push_back(spacing * spacing);
  if (method != Method::linear) P.half_size.push_back(Vec2(0.5 * spacing, 0.5 * spacing));
}

inline double wave_speed() { return std::sqrt(kSolid.p_wave_modulus() / kDensity); }

// dt = 0.3 h / c, well inside the CFL limit of an undeformed grid.
inline double stable_step(const Model& model) { return 0.3 * model.grid.h / wave_speed(); }

// Central-difference kicks: dt/2 on the first step, dt after.
inline void advance(Stepper& stepper, int steps, double dt) {
  double t = 0.0;
  for (int k = 0; k < steps; ++k) {
    stepper.step(t, dt, k == 0 ? 0.5 * dt : dt);
    t += dt;
  }
}

inline Vec2 total_momentum(const Particles& P) {
  Vec2 sum = Vec2::Zero();
  for (std::size_t p = 0; p < P.size(); ++p) sum += P.mass[p] * P.velocity[p];
  return sum;
}

inline double total_momentum_magnitude(const Particles& P) {
  double sum = 0.0;
  for (std::size_t p = 0; p < P.size(); ++p) sum += P.mass[p] * P.velocity[p].norm();
  return sum;
}

class NullObserver final : public mpmvv::RunObserver {};

// Records the time after every step.
class StepTimes final : public mpmvv::RunObserver {
 public:
  void after_step(double t, const Stepper&) override { times.push_back(t); }
  std::vector<double> times;
};

inline mpmvv::TimeLoopOptions short_run(double end_time) {
  mpmvv::TimeLoopOptions o;
  o.end_time = end_time;
  o.cfl = 0.3;
  o.output_times = {end_time};
  return o;
}

// A velocity field under which the disk shears and stretches everywhere and
// drifts, so that its total momentum is not zero.
inline void shear_and_stretch(Model& model) {
  for (std::size_t p = 0; p < model.particles.size(); ++p) {
    const Vec2 x = model.particles.position[p];
    model.particles.velocity[p] = Vec2(0.1 * std::sin(x.y()) + 0.02, 0.05 * x.x() - 0.01);
  }
}

}  // namespace mpmvv::testing::solver_models
