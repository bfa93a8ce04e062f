// The stages of the explicit step as one stepper holds them: its state between
// steps and, for each stage of solver/stages/, the variant this run takes,
// chosen once per stage (scheme, velocity transfer, body force, stored
// stencils, fault). The schemes that put them in order are schemes.hpp.
#pragma once

#include <chrono>
#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "../contact.hpp"
#include "../domain_angle.hpp"
#include "../domain_corners.hpp"
#include "../material/materials.hpp"
#include "../model.hpp"
#include "../monitors.hpp"
#include "../parallel.hpp"
#include "../shape/stored_stencils.hpp"
#include "../stages.hpp"
#include "../stepper.hpp"
#include "fault_state.hpp"
#include "grid_conditions.hpp"
#include "settings.hpp"

namespace mpmvv {

template <class Shape, class Material>
class ExplicitStages : public Stepper {
 protected:
  ExplicitStages(Model model, const StepSettings& settings, Material material, std::optional<Material> second_material,
                 SceneStages stages)
      : Stepper(std::move(model)),
        settings_(settings),
        faults_(settings.fault, model_.particles),
        viscosity_{settings.viscosity_linear, settings.viscosity_quadratic},
        materials_{material, std::move(second_material), stages.second_material_from},
        body_force_(std::move(stages.body_force)),
        traction_(std::move(stages.traction)),
        grid_(model_.grid, model_.particles, stages, settings.fault),
        bodies_(stages.second_body, model_.grid.node_count(), max_threads()) {
    buffers_.resize(max_threads(), model_.grid.node_count());
    if constexpr (requires { Shape::total_lagrangian; }) tracer_reference_ = model_.tracers;
    if (body_force_) {
      body_force_->prepare(model_.particles);
      model_.particles.body_force.assign(model_.particles.size(), Vec2::Zero());
    }
    if (traction_) traction_force_.resize(traction_->edges().size());
    if (settings_.scheme == Scheme::musl) next_position_.resize(model_.particles.size());
    // The affine part starts at zero: the first map is FLIP's. (pic-velocity
    // reads the grid's velocity as APIC does and never maps the affine part.)
    if (settings_.apic || faults_.is(SolverFault::pic_velocity))
      model_.particles.affine_velocity.assign(model_.particles.size(), Mat2::Zero());
    // The shape's form was chosen from the same angle (make_for_geometry).
    if ((settings_.open_cos < 1.0) != kTurnedDomains<Shape>)
      throw std::logic_error("min_domain_angle and the CPDI form it needs were chosen apart");
    if constexpr (kTurnedDomains<Shape>) start_domain_axes(model_.particles);
    if constexpr (kCornerDomains<Shape>) start_domain_corners(model_.particles);
    if (settings_.dilatation != Dilatation::particle) volume_sums_.resize(std::size_t(max_threads()));
  }

  Shape bind(const Particles& P, const Mat2* domain_deformation = nullptr) const {
    Shape shape = Shape::bind(model_.grid, P, domain_deformation, faults_.gradient_scale(Shape::name));
    if constexpr (requires { shape.weight_skew; })
      if (faults_.is(SolverFault::cpdi_weight)) shape.weight_skew = kFaultyCpdiWeightSkew;
    if constexpr (requires { shape.shear_sign; }) shape.shear_sign = faults_.shear_sign();
    return shape;
  }

  void walls(GridFields& g) const { grid_.walls(model_.grid, g); }

  // The first stage of USL and MUSL: mass, momentum and forces at t mapped to
  // the grid, with the scan of the state it weighs when `scan` is given
  // (prepare_step). Under USL a shape that stores its stencils records them
  // here for the update (stored_stencils.hpp).
  template <class Scan = NoScan>
  void map_step(double t, Scan* scan = nullptr) {
    const Shape shape = bind(model_.particles);
    if (body_force_) evaluate_body_force(t);
    if constexpr (kStoresStencils<Shape>) {
      if (settings_.scheme == Scheme::usl) {
        stencils_.resize(model_.particles.size());
        map_with_forces(StencilRecorder<Shape>{shape, stencils_.data()}, fields_, {}, scan);
        add_tractions(t);
        return;
      }
    }
    map_with_forces(shape, fields_, {}, scan);
    add_tractions(t);
  }

  // The map, unless prepare_step made it for this step.
  void map_unless_prepared(double t) {
    const bool prepared = mapped_at_ == t;
    mapped_at_ = kNotMapped;
    if (!prepared) map_step(t);
  }

  // Mass, momentum, the internal force and the body force (evaluated before)
  // of the particles of `range`, to field g.
  template <class S, class Scan = NoScan>
  void map_with_forces(const S& shape, GridFields& g, ParticleRange range = {}, Scan* scan = nullptr) {
    if (body_force_)
      momentum_to_grid<kMass | kMomentum | kInternalForce | kBodyForce>(shape, g, range, scan);
    else
      momentum_to_grid<kMass | kMomentum | kInternalForce>(shape, g, range, scan);
  }

  // USF's map after its stress update: the forces alone, with the body force
  // at t evaluated first.
  void map_forces(const Shape& shape, double t) {
    if (body_force_) evaluate_body_force(t);
    const StageClock clock(stage_times_.map);
    if (body_force_)
      particles_to_grid<kInternalForce | kBodyForce>(shape, model_.particles, buffers_, fields_);
    else
      particles_to_grid<kInternalForce>(shape, model_.particles, buffers_, fields_);
    add_tractions(t);
  }

  // The boundary tractions at t on the grid (traction.hpp), shared as the
  // method forms its internal force: CPDI's corner interpolation, or the
  // grid basis itself (under the total formulation, the reference basis's).
  void add_tractions(double t) {
    if (!traction_) return;
    constexpr bool total = requires { Shape::total_lagrangian; };
    constexpr bool corners = [] {
      if constexpr (total)
        return decltype(std::declval<Shape>().reference)::gradients_beyond_grid_basis;
      else
        return Shape::gradients_beyond_grid_basis;
    }();
    traction_->evaluate(t, traction_force_);
    faults_.after_traction(traction_force_);
    tractions_to_grid(model_.grid, model_.particles, traction_->edges(), traction_force_,
                      corners ? TractionRule::corners : TractionRule::exact, total, traction_shares_, fields_);
  }

  // The velocity transfer is chosen here, once per stage: under APIC every
  // map of momentum carries the particles' affine fields, and every velocity
  // update takes the grid's velocity and its gradient (model.hpp).
  template <unsigned Fields, class S, class Scan = NoScan>
  void momentum_to_grid(const S& shape, GridFields& g, ParticleRange range = {}, Scan* scan = nullptr) {
    const StageClock clock(stage_times_.map);
    if (settings_.apic)
      particles_to_grid<Fields | kAffineMomentum>(shape, model_.particles, buffers_, g, range, &model_.grid, scan);
    else
      particles_to_grid<Fields>(shape, model_.particles, buffers_, g, range, nullptr, scan);
    if constexpr ((Fields & kMass) != 0)
      if (faults_.is(SolverFault::consistent_mass)) lump_consistent_diagonal(bind(model_.particles), model_.particles, g, range);
  }

  // The grid velocity of the momentum just mapped, under the scene's
  // conditions: the velocity-only pass of USF (before the stress update) and
  // of MUSL (after the particles moved).
  void grid_velocity_with_boundaries(double t, double dt, double kick) {
    grid_velocity_from_momentum(fields_);
    grid_.on_velocity(model_.grid, fields_, t, dt, kick);
  }

  // USF's and MUSL's first map: mass and momentum, or momentum alone.
  void map_mass_and_momentum(const Shape& shape) { momentum_to_grid<kMass | kMomentum>(shape, fields_); }
  void map_momentum(const Shape& shape) { momentum_to_grid<kMomentum>(shape, fields_); }

  // The particles' velocities and positions from field g (into position_out
  // when given), and under USL F and V too.
  template <class S>
  void move_and_deform(const S& shape, const GridFields& g, double dt, double kick, ParticleRange range = {}) {
    velocities_from_grid<kVelocity | kPosition | kDeformation>(shape, g, dt, kick, nullptr, range);
  }
  void move_particles(const Shape& shape, double dt, double kick, Vec2* position_out = nullptr) {
    velocities_from_grid<kVelocity | kPosition>(shape, fields_, dt, kick, position_out);
  }

  template <unsigned Updates, class S>
  void velocities_from_grid(const S& shape, const GridFields& g, double dt, double kick,
                            Vec2* position_out = nullptr, ParticleRange range = {}) {
    const StageClock clock(stage_times_.update);
    deforming<(Updates & kDeformation) != 0>([&] {
      if (settings_.apic || faults_.is(SolverFault::pic_velocity))
        grid_to_particles<Updates | kAffine, S>(shape, g, model_.particles, dt, kick, position_out, range,
                                                &node_motion_);
      else
        grid_to_particles<Updates, S>(shape, g, model_.particles, dt, kick, position_out, range, &node_motion_);
    });
    if (settings_.apic) faults_.after_velocity_update(model_.particles);
  }

  // F and V alone from the grid velocity (USF, MUSL), the volumes remembered first.
  void deformation_from_grid(const Shape& shape, double dt, double kick) {
    viscosity_.remember_volumes(model_.particles);
    const StageClock clock(stage_times_.update);
    deforming([&] {
      grid_to_particles<kDeformation, Shape>(shape, fields_, model_.particles, dt, kick, nullptr, {}, &node_motion_);
    });
  }

  // A transfer that updates F and V (kDeformation), with the faults of those
  // updates applied after it: deformation-transpose, frozen-volume.
  template <bool Deforms = true, class Update>
  void deforming(Update&& update) {
    if constexpr (Deforms) faults_.before_deformation(model_.particles);
    update();
    if constexpr (Deforms) faults_.after_deformation(model_.particles);
  }

  // The constitutive update, after the locking remedy when the run has it,
  // then the bulk viscosity of the step's dilatation when it has that.
  void update_stress_of_particles(double dt) {
    const StageClock clock(stage_times_.stress);
    Particles& P = model_.particles;
    if (settings_.dilatation == Dilatation::cell_averaged)
      average_cell_dilatation<Shape::geometry>(model_.grid, P, volume_sums_);
    if (settings_.dilatation == Dilatation::node_smoothed)
      smooth_node_dilatation(bind(P), P, volume_sums_, model_.grid.node_count());
    faults_.before_constitutive_update(P);
    for_each_material([&](const Material& m, std::size_t begin, std::size_t end) {
      if (faults_.is(SolverFault::wrong_shear_modulus))
        update_stress<Shape::geometry>(with_faulty_shear_modulus(m), P, begin, end);
      else
        update_stress<Shape::geometry>(m, P, begin, end);
    });
    faults_.after_constitutive_update(P);
    if (viscosity_.on()) {
      viscosity_.ratio = 0.0;
      for_each_material([&](const Material& m, std::size_t begin, std::size_t end) {
        const ViscousStep v = add_bulk_viscosity(bind(P), P, viscosity_.volume_before, m.p_wave_modulus(),
                                                 model_.grid.h, viscosity_.linear, viscosity_.quadratic, dt, begin, end);
        ledger_.damping -= v.dissipated;
        viscosity_.ratio = std::max(viscosity_.ratio, v.max_ratio);
      });
    }
    faults_.after_stress_update(P);
  }

  // Calls f(material, begin, end) for each material and the particles it holds.
  template <class F>
  void for_each_material(F&& f) const {
    materials_.for_each(model_.particles.size(), f);
  }

  // A scan's signal speed as the step's stability needs it: raised by the
  // bulk viscosity, or frozen under frozen-time-step.
  ParticleScan stable(ParticleScan s) const {
    if (viscosity_.on()) s.max_signal_speed *= viscosity_.signal_speed_factor();
    return faults_.scanned(s);
  }

  // The grid's motion from the node sums under the scene's conditions
  // (grid_conditions.hpp), for one body or for two on their own fields.
  void advance_grid(const Shape& shape, double t, double dt, double kick) {
    const StageClock clock(stage_times_.grid);
    grid_.advance(shape, model_.particles, model_.grid, fields_, t, dt, kick, books());
  }
  void advance_grids_of_bodies(double t, double dt, double kick) {
    grid_.advance_bodies(model_.grid, fields_, bodies_.fields, t, dt, kick, books());
  }
  GridBooks books() { return {ledger_, reactions_, contact_forces_}; }

  // The body force's and the tractions' work over the step (the ledger's
  // body work holds both; results-format.md).
  void book_body_work(double dt) {
    if (body_force_) ledger_.body += dt * body_force_power(model_.particles);
    if (traction_) ledger_.body += dt * traction_power(traction_shares_, fields_);
  }

  void evaluate_body_force(double t) {
    const auto start = std::chrono::steady_clock::now();
    Particles& P = model_.particles;
    t = faults_.force_time(t);
    faults_.before_force(*body_force_, P);
    body_force_->evaluate(t, P, P.body_force);
    forcing_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  void move_tracers(double dt) {
    if (model_.tracers.empty()) return;
    const StageClock clock(stage_times_.update);
    if constexpr (requires { Shape::total_lagrangian; })
      advect_tracers(model_.grid, fields_, model_.tracers, dt, &tracer_reference_);
    else
      advect_tracers(model_.grid, fields_, model_.tracers, dt);
  }

  // Corner domains move with the velocity the particles just moved with, after
  // the last transfer that weighs the step's domains; into `to` when those are
  // still needed (MUSL), else in place.
  void move_domain_corners(double dt, std::vector<Vec2>* to = nullptr) {
    if constexpr (kCornerDomains<Shape>) {
      const StageClock clock(stage_times_.update);
      std::vector<Vec2>& corners = model_.particles.domain_corner;
      move_corners(model_.grid, fields_, corners, to ? *to : corners, dt);
    }
  }

  const StepSettings settings_;
  FaultState faults_;
  BulkViscosity viscosity_;
  std::vector<std::vector<double>> volume_sums_;  // dilatation remedies: per-thread cell or node volume sums
  // The time of the step whose map prepare_step made, or kNotMapped.
  static constexpr double kNotMapped = -std::numeric_limits<double>::infinity();
  double mapped_at_ = kNotMapped;
  // USL: each particle's stencil from the map, read back by the update (stored_stencils.hpp)
  std::vector<Stencil<Shape::stencil_size>> stencils_;
  Materials<Material> materials_;
  std::shared_ptr<BodyForce> body_force_;
  std::shared_ptr<BoundaryTraction> traction_;
  std::vector<Vec2> traction_force_;        // each side's force at the last map
  std::vector<NodeForce> traction_shares_;  // the nodes' shares of it, for its work
  GridConditions<Shape> grid_;  // what the scene does to the grid's motion
  SecondBody bodies_;  // two bodies in contact (contact.hpp); bodies_.first = 0: one body
  ScatterBuffers buffers_;
  std::vector<double> node_motion_;  // grid_to_particles' packed a_g and v_g^L
  std::vector<Vec2> next_position_;  // MUSL only: x_{n+1} while x_n still sets the weights
  std::vector<std::size_t> split_parents_;  // split_long_domains: the particles a split cut in the last step
  std::vector<Vec2> next_corner_;    // MUSL with corner domains: the corners at t_{n+1}, likewise
  std::vector<Mat2> step_start_deformation_;  // USF with CPDI only: F_n, which sets the domains
  std::vector<Vec2> tracer_reference_;         // total Lagrangian: where each tracer reads the grid
};

}  // namespace mpmvv
