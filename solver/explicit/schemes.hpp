// The explicit MPM step: the three schemes side by side
// (002_c3305cb8b1bc1490.txt section 1.5), each the stages of one step in
// their order (the stages are stages.hpp), and what the time loop asks of a
// stepper between steps (stepper.hpp).
#pragma once

#include <cmath>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "../io/state_archive.hpp"
#include "../largest_frequency.hpp"
#include "../split.hpp"
#include "diagnose.hpp"
#include "stages.hpp"

namespace mpmvv {

template <class Shape, class Material>
class ExplicitStepper final : public ExplicitStages<Shape, Material> {
  using Stages = ExplicitStages<Shape, Material>;
  // The stages and the state of the step (stages.hpp), and the stepper's own (stepper.hpp).
  using Stages::bind, Stages::map_step, Stages::map_unless_prepared, Stages::map_with_forces,
      Stages::map_forces, Stages::map_mass_and_momentum, Stages::map_momentum, Stages::move_and_deform,
      Stages::move_particles,
      Stages::grid_velocity_with_boundaries, Stages::deformation_from_grid,
      Stages::update_stress_of_particles, Stages::advance_grid, Stages::advance_grids_of_bodies,
      Stages::book_body_work, Stages::evaluate_body_force, Stages::move_tracers, Stages::move_domain_corners,
      Stages::for_each_material, Stages::stable, Stages::walls;
  using Stages::settings_, Stages::faults_, Stages::viscosity_, Stages::mapped_at_, Stages::kNotMapped,
      Stages::stencils_, Stages::materials_, Stages::body_force_, 
      Stages::bodies_, Stages::next_position_, Stages::next_corner_, Stages::split_parents_,
      Stages::step_start_deformation_, Stages::tracer_reference_;
  using Stages::model_, Stages::fields_, Stages::stage_times_, Stages::contact_forces_;

 public:
  ExplicitStepper(Model model, const StepSettings& settings, Material material,
                  std::optional<Material> second_material, SceneStages stages)
      : Stages(std::move(model), settings, std::move(material), std::move(second_material), std::move(stages)) {}

  void step(double t, double dt, double kick) override {
    switch (settings_.scheme) {
      case Scheme::usl: step_usl(t, dt, kick); break;
      case Scheme::usf: step_usf(t, dt, kick); break;
      case Scheme::musl: step_musl(t, dt, kick); break;
    }
    // Between steps, where no stage holds the particle arrays: domains are
    // turned first, and a split then halves the turned domain.
    if constexpr (Shape::reads_deformation_gradient) {
      if constexpr (kTurnedDomains<Shape>) open_sheared_domains(model_.particles, settings_.open_cos);
      const std::size_t before = model_.particles.size();
      split_parents_.clear();
      if (settings_.split_length > 0.0 &&
          split_long_domains(model_.particles, settings_.split_length, &split_parents_) > 0) {
        if (settings_.scheme == Scheme::musl) next_position_.resize(model_.particles.size());
        if (body_force_) body_force_->update(model_.particles, before, split_parents_);
      }
    }
  }

 private:
  // Update stress last (002_c3305cb8b1bc1490.txt section 1.5): forces from the
  // stress at t_n, then velocity, position, F and finally stress.
  void step_usl(double t, double dt, double kick) {
    if (bodies_.first > 0) {
      step_usl_two_bodies(t, dt, kick);
      return;
    }
    const Shape shape = bind(model_.particles);
    map_unless_prepared(t);
    advance_grid(shape, t, dt, kick);
    move_tracers(dt);
    viscosity_.remember_volumes(model_.particles);
    if constexpr (kStoresStencils<Shape>)
      move_and_deform(StencilReader<Shape>{shape, stencils_.data()}, fields_, dt, kick);
    else
      move_and_deform(shape, fields_, dt, kick);
    move_domain_corners(dt);
    update_stress_of_particles(dt);
    book_body_work(dt);
  }

  // Update stress first: F and stress from the grid velocity at t_n, then the
  // forces of the new stress move the grid and the particles. All transfers of
  // the step use the weights of the start of the step: the mass that divides
  // the forces is the mass the velocities are read back with, which is what
  // conserves momentum. CPDI domains therefore come from a copy of F_n.
  void step_usf(double t, double dt, double kick) {
    Particles& P = model_.particles;
    const Mat2* domain_deformation = nullptr;
    if constexpr (Shape::reads_deformation_gradient) {
      step_start_deformation_ = P.deformation_gradient;
      domain_deformation = step_start_deformation_.data();
    }
    const Shape shape = bind(P, domain_deformation);
    map_mass_and_momentum(shape);
    grid_velocity_with_boundaries(t, dt, kick);
    deformation_from_grid(shape, dt, kick);
    update_stress_of_particles(dt);
    map_forces(shape, t);
    advance_grid(shape, t, dt, kick);
    move_tracers(dt);
    move_particles(shape, dt, kick);
    move_domain_corners(dt);
    book_body_work(dt);
  }

  // Modified USL: as USL, but the velocity gradient comes from the particle
  // velocities at t_{n+1} mapped back to the grid, with the weights at x_n.
  void step_musl(double t, double dt, double kick) {
    Particles& P = model_.particles;
    const Shape shape = bind(P);
    map_unless_prepared(t);
    advance_grid(shape, t, dt, kick);
    move_tracers(dt);
    move_particles(shape, dt, kick, next_position_.data());
    move_domain_corners(dt, &next_corner_);
    map_momentum(shape);
    grid_velocity_with_boundaries(t, dt, kick);
    deformation_from_grid(shape, dt, kick);
    P.position.swap(next_position_);
    if constexpr (kCornerDomains<Shape>) P.domain_corner.swap(next_corner_);
    update_stress_of_particles(dt);
    book_body_work(dt);
  }

  // USL for two bodies in contact (contact.hpp): each body maps to its own
  // grid field, the fields advance apart, the contact corrects them where both
  // bodies reach a node, and each body reads back its own field.
  void step_usl_two_bodies(double t, double dt, double kick) {
    Particles& P = model_.particles;
    const Shape shape = bind(P);
    const ParticleRange a{0, bodies_.first}, b{bodies_.first, P.size()};
    if (body_force_) evaluate_body_force(t);
    map_with_forces(shape, fields_, a);
    map_with_forces(shape, bodies_.fields, b);
    mass_gradient_to_grid(shape, P, a.first, a.last, bodies_.buffers, bodies_.gradient_a);
    mass_gradient_to_grid(shape, P, b.first, P.size(), bodies_.buffers, bodies_.gradient_b);
    advance_grids_of_bodies(t, dt, kick);
    apply_body_contact(fields_, bodies_.fields, bodies_.gradient_a, bodies_.gradient_b, kick, contact_forces_);
    move_tracers(dt);
    viscosity_.remember_volumes(P);
    move_and_deform(shape, fields_, dt, kick, a);
    move_and_deform(shape, bodies_.fields, dt, kick, b);
    update_stress_of_particles(dt);
    book_body_work(dt);
  }

 public:
  bool restartable() const override { return true; }

  // Besides the particles: what a step leaves for the next (the bulk
  // viscosity's ratio, the total formulation's tracer references) and what
  // the faults hold. The rest is rebuilt by the next map or is scratch within
  // a step; the body force's per-particle factors are prepared again from
  // the particles read, by the functions that made them.
  void persist(StateArchive& a) override {
    Stepper::persist(a);
    a.field("viscous_ratio", viscosity_.ratio);
    a.field("tracer_reference", tracer_reference_);
    faults_.persist(a);
    if (!a.reads()) return;
    mapped_at_ = kNotMapped;
    if (body_force_) body_force_->prepare(model_.particles);
    if (settings_.scheme == Scheme::musl) next_position_.resize(model_.particles.size());
  }

  ParticleScan scan() const override {
    const StageClock clock(stage_times_.scan);
    const Shape shape = bind(model_.particles);
    ParticleScan s;
    s.first_unhealthy = model_.particles.size();
    for_each_material([&](const Material& m, std::size_t begin, std::size_t end) {
      s = combined(s, scan_particles(shape, m, model_.particles, model_.grid.h, begin, end));
    });
    return stable(s);
  }

  // USL and MUSL of one body of one material map mass, momentum and forces
  // first, with no dt: that map scans too (stages.hpp: ScanInMap), and the
  // scan evaluates no stencil of its own.
  ParticleScan prepare_step(double t) override {
    const bool maps_first = settings_.scheme != Scheme::usf && bodies_.first == 0 && !materials_.second;
    if (!maps_first) return scan();
    const Shape shape = bind(model_.particles);
    ScanInMap<Shape, Material> scanning{shape, materials_.first, model_.particles, model_.grid.h};
    map_step(t, &scanning);
    const ParticleScan s = scanning.result;
    // An unhealthy particle was left out of the map: the run stops here.
    if (s.first_unhealthy == model_.particles.size()) mapped_at_ = t;
    return stable(s);
  }

  double bytes_per_particle() const override {
    const std::size_t n = model_.particles.size();
    const std::size_t own = bytes_held(stencils_) + bytes_held(next_position_) + bytes_held(next_corner_) +
                            bytes_held(step_start_deformation_) + bytes_held(viscosity_.volume_before) +
                            (body_force_ ? body_force_->bytes() : 0);
    return n ? double(model_.particles.bytes() + own) / double(n) : 0.0;
  }

  Monitors monitors() const override {
    const Shape shape = bind(model_.particles);
    Monitors m;
    for_each_material([&](const Material& material, std::size_t begin, std::size_t end) {
      m = combined(m, monitor_particles(shape, material, model_.particles, model_.grid, begin, end));
    });
    return m;
  }

  DomainPolygons domain_polygons() const override {
    return mpmvv::domain_polygons(bind(model_.particles), model_.particles, model_.grid);
  }

  // omega_max of the step's own linearization (largest_frequency.hpp).
  double largest_frequency(int iterations) const override {
    return grid_largest_frequency(
        model_.particles, model_.grid, iterations, [&](const Particles& P) { return bind(P); },
        [&](GridFields& g) { walls(g); },
        [&](Particles& moved) {
          for_each_material([&](const Material& m, std::size_t begin, std::size_t end) {
            update_stress<Shape::geometry>(m, moved, begin, end);
          });
        });
  }

  ParticleFault diagnose(std::size_t p) const override {
    return diagnose_particle(bind(model_.particles), model_.particles, model_.grid, p);
  }
};

}  // namespace mpmvv
