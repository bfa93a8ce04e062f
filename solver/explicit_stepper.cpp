#include "explicit_stepper.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "domain_angle.hpp"
#include "domain_corners.hpp"
#include "largest_frequency.hpp"
#include "rest_points.hpp"
#include "split.hpp"
#include "shape/cpdi.hpp"
#include "shape/cpdi_exact.hpp"
#include "shape/bspline.hpp"
#include "shape/gimp.hpp"
#include "shape/linear.hpp"
#include "shape/stored_stencils.hpp"
#include "shape/total_lagrangian.hpp"
#include "monitors.hpp"
#include "io/state_archive.hpp"

namespace mpmvv {

const char* to_string(Method m) {
  switch (m) {
    case Method::linear: return "linear";
    case Method::gimp: return "gimp";
    case Method::cpdi: return "cpdi";
    case Method::cpdi_exact: return "cpdi-exact";
    case Method::bspline: return "bspline";
    case Method::bspline_cubic: return "bspline-cubic";
  }
  return "?";
}

const char* to_string(Scheme s) {
  switch (s) {
    case Scheme::usl: return "usl";
    case Scheme::usf: return "usf";
    case Scheme::musl: return "musl";
  }
  return "?";
}

double p_wave_modulus(const MaterialModel& m) {
  return std::visit([](const auto& material) { return material.p_wave_modulus(); }, m);
}

namespace {

// What make_stepper chose for the step beside its shape and material, each
// from SolverOptions (model.hpp).
struct StepSettings {
  Scheme scheme;
  bool apic;            // velocity_transfer = apic
  SolverFault fault;    // none, but in a fault-injection test (faults.hpp)
  Dilatation dilatation;
  double split_length;  // CPDI domains longer than this are split in two (split.hpp); 0: never
  double open_cos;      // CPDI domains whose sides meet at |cos| above this are turned (domain_angle.hpp); 1: never
  double viscosity_linear, viscosity_quadratic;  // bulk viscosity C0, C1 (add_bulk_viscosity); 0: none
};

// The cosine above which open_sheared_domains acts, from the angle in degrees below
// which a domain is turned; 1 (never) for 0.
inline double min_domain_angle_cosine(double degrees) {
  return degrees > 0.0 ? std::cos(degrees * std::numbers::pi / 180.0) : 1.0;
}

StepSettings step_settings(const SolverOptions& o, double h) {
  return {o.scheme,
          o.velocity_transfer == VelocityTransfer::apic,
          o.fault,
          o.dilatation,
          o.split_domains_beyond * h,
          min_domain_angle_cosine(o.min_domain_angle),
          o.bulk_viscosity_linear,
          o.bulk_viscosity_quadratic};
}

template <class Shape, class Material>
class ExplicitStepper final : public Stepper {
 public:
  ExplicitStepper(Model model, const StepSettings& settings, Material material, std::optional<Material> second_material,
                  SceneStages stages)
      : Stepper(std::move(model)),
        scheme_(settings.scheme),
        apic_(settings.apic),
        fault_(settings.fault),
        gradient_scale_(settings.fault == SolverFault::cpdi_gradient ? kFaultyCpdiGradientScale : 1.0),
        dilatation_(settings.dilatation),
        split_length_(settings.split_length),
        open_cos_(settings.open_cos),
        viscosity_linear_(settings.viscosity_linear),
        viscosity_quadratic_(settings.viscosity_quadratic),
        material_(material),
        second_material_(std::move(second_material)),
        second_material_from_(stages.second_material_from),
        body_force_(std::move(stages.body_force)),
        constraints_(std::move(stages.constraints)),
        rest_(stages.rest_points.empty()
                  ? std::nullopt
                  : std::optional<RestPoints>(std::in_place,
                        basis_rows<typename Shape::GridBasis>(model_.grid, stages.rest_points),
                        prescribed_components(model_.grid.node_count(), constraints_))),
        damping_(stages.damping),
        contact_(std::move(stages.contact)),
        second_(stages.second_body) {
    buffers_.resize(max_threads(), model_.grid.node_count());
    if constexpr (requires { Shape::total_lagrangian; }) tracer_reference_ = model_.tracers;
    if (body_force_) {
      body_force_->prepare(model_.particles);
      model_.particles.body_force.assign(model_.particles.size(), Vec2::Zero());
    }
    if (scheme_ == Scheme::musl) next_position_.resize(model_.particles.size());
    // The affine part starts at zero: the first map is FLIP's. (pic-velocity
    // reads the grid's velocity as APIC does and never maps the affine part.)
    if (apic_ || fault_ == SolverFault::pic_velocity)
      model_.particles.affine_velocity.assign(model_.particles.size(), Mat2::Zero());
    if (fault_ == SolverFault::lagged_stress) held_stress_ = model_.particles.stress;
    // The shape's form was chosen from the same angle (make_for_geometry).
    if ((open_cos_ < 1.0) != kTurnedDomains)
      throw std::logic_error("min_domain_angle and the CPDI form it needs were chosen apart");
    if constexpr (kTurnedDomains) start_domain_axes(model_.particles);
    if constexpr (kCornerDomains) start_domain_corners(model_.particles);
    if (dilatation_ != Dilatation::particle) volume_sums_.resize(std::size_t(max_threads()));
    if (damping_ > 0.0) fixed_components_ = prescribed_components(model_.grid.node_count(), constraints_);
    if (second_ > 0) {
      fields_b_.resize(model_.grid.node_count());
      gradient_a_.assign(model_.grid.node_count(), Vec2::Zero());
      gradient_b_.assign(model_.grid.node_count(), Vec2::Zero());
      gradient_buffers_.resize(std::size_t(max_threads()));
    }
  }

  void step(double t, double dt, double kick) override {
    switch (scheme_) {
      case Scheme::usl: step_usl(t, dt, kick); break;
      case Scheme::usf: step_usf(t, dt, kick); break;
      case Scheme::musl: step_musl(t, dt, kick); break;
    }
    // Between steps, where no stage holds the particle arrays: domains are
    // turned first, and a split then halves the turned domain.
    if constexpr (Shape::reads_deformation_gradient) {
      if constexpr (kTurnedDomains) open_sheared_domains(model_.particles, open_cos_);
      const std::size_t before = model_.particles.size();
      split_parents_.clear();
      if (split_length_ > 0.0 && split_long_domains(model_.particles, split_length_, &split_parents_) > 0) {
        if (scheme_ == Scheme::musl) next_position_.resize(model_.particles.size());
        if (body_force_) body_force_->update(model_.particles, before, split_parents_);
      }
    }
  }

  bool restartable() const override { return true; }

  // Besides the particles: what a step leaves for the next (the bulk
  // viscosity's ratio, the total formulation's tracer references) and what
  // the faults hold. The rest is rebuilt by the next map or is scratch within
  // a step; the body force's per-particle factors are prepared again from
  // the particles read, by the functions that made them.
  void persist(StateArchive& a) override {
    Stepper::persist(a);
    a.field("viscous_ratio", viscous_ratio_);
    a.field("tracer_reference", tracer_reference_);
    a.field("held_deformation", held_deformation_);
    a.field("held_stress", held_stress_);
    a.field("force_time", force_time_);
    a.field("first_signal_speed", first_signal_speed_);
    if (!a.reads()) return;
    mapped_at_ = kNotMapped;
    if (body_force_) body_force_->prepare(model_.particles);
    if (scheme_ == Scheme::musl) next_position_.resize(model_.particles.size());
  }

  // With bulk viscosity the fastest grid mode is damped at the ratio xi of the
  // last step, and central differences are stable to dt = (2 / omega)
  // (sqrt(1 + xi^2) - xi): the signal speed grows by sqrt(1 + xi^2) + xi.
  ParticleScan scan() const override {
    const StageClock clock(stage_times_.scan);
    const Shape shape = bind(model_.particles);
    ParticleScan s;
    s.first_unhealthy = model_.particles.size();
    for_each_material([&](const Material& m, std::size_t begin, std::size_t end) {
      s = combined(s, scan_particles(shape, m, model_.particles, model_.grid.h, begin, end));
    });
    if (viscous()) s.max_signal_speed *= std::sqrt(1.0 + viscous_ratio_ * viscous_ratio_) + viscous_ratio_;
    return frozen_if_faulty(s);
  }

  // USL and MUSL of one body of one material map mass, momentum and forces
  // first, with no dt: that map scans too (stages.hpp: ScanInMap), and the
  // scan evaluates no stencil of its own.
  ParticleScan prepare_step(double t) override {
    const bool maps_first = scheme_ != Scheme::usf && second_ == 0 && !second_material_;
    if (!maps_first) return scan();
    const Shape shape = bind(model_.particles);
    ScanInMap<Shape, Material> scanning{shape, material_, model_.particles, model_.grid.h};
    map_step(t, &scanning);
    ParticleScan s = scanning.result;
    // An unhealthy particle was left out of the map: the run stops here.
    if (s.first_unhealthy == model_.particles.size()) mapped_at_ = t;
    if (viscous()) s.max_signal_speed *= std::sqrt(1.0 + viscous_ratio_ * viscous_ratio_) + viscous_ratio_;
    return frozen_if_faulty(s);
  }

  // frozen-time-step: the signal speed of the first scan, kept.
  ParticleScan frozen_if_faulty(ParticleScan s) const {
    if (fault_ != SolverFault::frozen_time_step) return s;
    if (!(first_signal_speed_ > 0.0)) first_signal_speed_ = s.max_signal_speed;
    s.max_signal_speed = first_signal_speed_;
    return s;
  }

  double bytes_per_particle() const override {
    const std::size_t n = model_.particles.size();
    const std::size_t own = bytes_held(stencils_) + bytes_held(next_position_) + bytes_held(next_corner_) +
                            bytes_held(step_start_deformation_) + bytes_held(volume_before_) +
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
    const Particles& P = model_.particles;
    const Shape shape = bind(P);
    const Vec2& x = P.position[p];
    if (!(x.allFinite() && P.velocity[p].allFinite() && P.deformation_gradient[p].allFinite() &&
          P.stress[p].allFinite()))
      return {"nan", fmt::format("non-finite state at x = ({:.6g}, {:.6g})", x.x(), x.y())};
    if constexpr (Shape::geometry == Geometry::axisymmetric)
      if (!std::isfinite(P.hoop_stress[p]))
        return {"nan", fmt::format("non-finite hoop stress at x = ({:.6g}, {:.6g})", x.x(), x.y())};
    const double J = determinant(P.deformation_gradient[p]) * out_of_plane_stretch<Shape::geometry>(P, p);
    if (!(J > 0.0)) return {"non-positive J", fmt::format("J = {:.6g} at x = ({:.6g}, {:.6g})", J, x.x(), x.y())};
    if (!shape.inside(p)) {
      if (!inside_walls(model_.grid, x))
        return {"outside grid", fmt::format("the particle at ({:.6g}, {:.6g}) has crossed a wall", x.x(), x.y())};
      if constexpr (requires { shape.clear_of_walls(p); })
        if (!shape.clear_of_walls(p))
          return {"outside grid", fmt::format("the particle at ({:.6g}, {:.6g}) has come closer to a wall than its "
                                              "B-spline support allows (half a cell quadratic, a cell cubic: it "
                                              "would reach the mirrored ghost nodes)",
                                              x.x(), x.y())};
      if constexpr (requires { shape.within_stencil(p); })
        if (!shape.within_stencil(p))
          return {"domain too wide", fmt::format("the domain of the particle at ({:.6g}, {:.6g}) spans more cells "
                                                 "than its stencil holds", x.x(), x.y())};
      return {"outside grid", fmt::format("support of the particle at ({:.6g}, {:.6g}) leaves the grid", x.x(), x.y())};
    }
    return {"", ""};
  }

 private:
  // The three schemes side by side (002_c3305cb8b1bc1490.txt section 1.5),
  // each the stages of one step in their order; the stages are below them.
  //
  // Update stress last (002_c3305cb8b1bc1490.txt section 1.5): forces from the
  // stress at t_n, then velocity, position, F and finally stress.
  void step_usl(double t, double dt, double kick) {
    if (second_ > 0) {
      step_usl_two_bodies(t, dt, kick);
      return;
    }
    const Shape shape = bind(model_.particles);
    map_unless_prepared(t);
    advance_grid(shape, t, dt, kick);
    move_tracers(dt);
    remember_volumes();
    if constexpr (kStoresStencils<Shape>)
      velocities_from_grid<kVelocity | kPosition | kDeformation>(StencilReader<Shape>{shape, stencils_.data()},
                                                                 fields_, dt, kick);
    else
      velocities_from_grid<kVelocity | kPosition | kDeformation>(shape, fields_, dt, kick);
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
    momentum_to_grid<kMass | kMomentum>(shape, fields_);
    grid_velocity_from_momentum(fields_);
    walls(fields_);
    if (!constraints_.empty()) apply_constraints(constraints_, t, dt, kick, fields_);
    if (rest_) rest_->apply(fields_, kick);
    remember_volumes();
    {
      const StageClock clock(stage_times_.update);
      deforming([&] { grid_to_particles<kDeformation, Shape>(shape, fields_, P, dt, kick, nullptr, {}, &node_motion_); });
    }
    update_stress_of_particles(dt);
    if (body_force_) evaluate_body_force(t);
    {
      const StageClock clock(stage_times_.map);
      if (body_force_)
        particles_to_grid<kInternalForce | kBodyForce>(shape, P, buffers_, fields_);
      else
        particles_to_grid<kInternalForce>(shape, P, buffers_, fields_);
    }
    advance_grid(shape, t, dt, kick);
    move_tracers(dt);
    velocities_from_grid<kVelocity | kPosition>(shape, fields_, dt, kick);
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
    velocities_from_grid<kVelocity | kPosition>(shape, fields_, dt, kick, next_position_.data());
    move_domain_corners(dt, &next_corner_);
    momentum_to_grid<kMomentum>(shape, fields_);
    grid_velocity_from_momentum(fields_);
    walls(fields_);
    if (!constraints_.empty()) apply_constraints(constraints_, t, dt, kick, fields_);
    if (rest_) rest_->apply(fields_, kick);
    remember_volumes();
    {
      const StageClock clock(stage_times_.update);
      deforming([&] { grid_to_particles<kDeformation, Shape>(shape, fields_, P, dt, kick, nullptr, {}, &node_motion_); });
    }
    P.position.swap(next_position_);
    if constexpr (kCornerDomains) P.domain_corner.swap(next_corner_);
    update_stress_of_particles(dt);
    book_body_work(dt);
  }

  // Corner domains move with the velocity the particles just moved with, after
  // the last transfer that weighs the step's domains; into `to` when those are
  // still needed (MUSL), else in place.
  void move_domain_corners(double dt, std::vector<Vec2>* to = nullptr) {
    if constexpr (kCornerDomains) {
      const StageClock clock(stage_times_.update);
      std::vector<Vec2>& corners = model_.particles.domain_corner;
      move_corners(model_.grid, fields_, corners, to ? *to : corners, dt);
    }
  }

  // USL for two bodies in contact (contact.hpp): each body maps to its own
  // grid field, the fields advance apart, the contact corrects them where both
  // bodies reach a node, and each body reads back its own field.
  void step_usl_two_bodies(double t, double dt, double kick) {
    Particles& P = model_.particles;
    const Shape shape = bind(P);
    const ParticleRange a{0, second_}, b{second_, P.size()};
    if (body_force_) evaluate_body_force(t);
    for (const auto& [range, field] : {std::pair{a, &fields_}, std::pair{b, &fields_b_}}) {
      if (body_force_)
        momentum_to_grid<kMass | kMomentum | kInternalForce | kBodyForce>(shape, *field, range);
      else
        momentum_to_grid<kMass | kMomentum | kInternalForce>(shape, *field, range);
    }
    mass_gradient_to_grid(shape, P, a.first, a.last, gradient_buffers_, gradient_a_);
    mass_gradient_to_grid(shape, P, b.first, P.size(), gradient_buffers_, gradient_b_);
    std::vector<double> reactions(constraints_.size(), 0.0);
    for (GridFields* field : {&fields_, &fields_b_}) {
      update_grid_motion(*field, kick);
      if (damping_ > 0.0) damp_grid_motion(*field, damping_, kick);
      walls(*field);
      if (!constraints_.empty()) {
        const std::vector<double> r = apply_constraints(constraints_, t, dt, kick, *field);
        for (std::size_t k = 0; k < r.size(); ++k) reactions[k] += r[k];
      }
      if (damping_ > 0.0) ledger_.damping += dt * damping_power(model_.grid, *field, damping_, fixed_components_);
    }
    reactions_ = reactions;
    if (!constraints_.empty()) book_constraint_work(t, dt);
    apply_body_contact(fields_, fields_b_, gradient_a_, gradient_b_, kick, contact_forces_);
    move_tracers(dt);
    remember_volumes();
    velocities_from_grid<kVelocity | kPosition | kDeformation>(shape, fields_, dt, kick, nullptr, a);
    velocities_from_grid<kVelocity | kPosition | kDeformation>(shape, fields_b_, dt, kick, nullptr, b);
    update_stress_of_particles(dt);
    book_body_work(dt);
  }

  Shape bind(const Particles& P, const Mat2* domain_deformation = nullptr) const {
    Shape shape = Shape::bind(model_.grid, P, domain_deformation, gradient_scale_);
    if constexpr (requires { shape.weight_skew; })
      if (fault_ == SolverFault::cpdi_weight) shape.weight_skew = kFaultyCpdiWeightSkew;
    return shape;
  }

  // The walls (stages.hpp), or under swapped-walls the tangential component held.
  void walls(GridFields& g) const { apply_walls(model_.grid, g, fault_ == SolverFault::swapped_walls); }

  // The first stage of USL and MUSL: mass, momentum and forces at t mapped to
  // the grid, with the scan of the state it weighs when `scan` is given
  // (prepare_step). Under USL a shape that stores its stencils records them
  // here for the update (stored_stencils.hpp).
  template <class Scan = NoScan>
  void map_step(double t, Scan* scan = nullptr) {
    const Shape shape = bind(model_.particles);
    if constexpr (kStoresStencils<Shape>) {
      if (scheme_ == Scheme::usl) {
        stencils_.resize(model_.particles.size());
        map_mass_momentum_and_forces(StencilRecorder<Shape>{shape, stencils_.data()}, t, scan);
        return;
      }
    }
    map_mass_momentum_and_forces(shape, t, scan);
  }

  // The map, unless prepare_step made it for this step.
  void map_unless_prepared(double t) {
    const bool prepared = mapped_at_ == t;
    mapped_at_ = kNotMapped;
    if (!prepared) map_step(t);
  }

  template <class S, class Scan = NoScan>
  void map_mass_momentum_and_forces(const S& shape, double t, Scan* scan = nullptr) {
    if (body_force_) {
      evaluate_body_force(t);
      momentum_to_grid<kMass | kMomentum | kInternalForce | kBodyForce>(shape, fields_, {}, scan);
    } else {
      momentum_to_grid<kMass | kMomentum | kInternalForce>(shape, fields_, {}, scan);
    }
  }

  // The velocity transfer is chosen here, once per stage: under APIC every
  // map of momentum carries the particles' affine fields, and every velocity
  // update takes the grid's velocity and its gradient (model.hpp).
  template <unsigned Fields, class S, class Scan = NoScan>
  void momentum_to_grid(const S& shape, GridFields& g, ParticleRange range = {}, Scan* scan = nullptr) {
    const StageClock clock(stage_times_.map);
    if (apic_)
      particles_to_grid<Fields | kAffineMomentum>(shape, model_.particles, buffers_, g, range, &model_.grid, scan);
    else
      particles_to_grid<Fields>(shape, model_.particles, buffers_, g, range, nullptr, scan);
    if constexpr ((Fields & kMass) != 0)
      if (fault_ == SolverFault::consistent_mass) lump_consistent_diagonal(g, range);
  }

  // consistent-mass: m_g = sum_p m_p S_gp^2.
  void lump_consistent_diagonal(GridFields& g, ParticleRange range) const {
    const Particles& P = model_.particles;
    const Shape shape = bind(P);
    std::fill(g.mass.begin(), g.mass.end(), 0.0);
    Stencil<Shape::stencil_size> st;
    for (std::size_t p = range.first; p < range.end(P); ++p) {
      shape.evaluate(p, st);
      for (int k = 0; k < st.count; ++k) g.mass[st.node[k]] += P.mass[p] * st.weight[k] * st.weight[k];
    }
  }
  template <unsigned Updates, class S>
  void velocities_from_grid(const S& shape, const GridFields& g, double dt, double kick,
                            Vec2* position_out = nullptr, ParticleRange range = {}) {
    const StageClock clock(stage_times_.update);
    deforming<(Updates & kDeformation) != 0>([&] {
      if (apic_ || fault_ == SolverFault::pic_velocity)
        grid_to_particles<Updates | kAffine, S>(shape, g, model_.particles, dt, kick, position_out, range,
                                                &node_motion_);
      else
        grid_to_particles<Updates, S>(shape, g, model_.particles, dt, kick, position_out, range, &node_motion_);
    });
  }

  // A transfer that updates F and V (kDeformation), with the faults of those
  // updates applied after it: deformation-transpose, frozen-volume.
  template <bool Deforms = true, class Update>
  void deforming(Update&& update) {
    Particles& P = model_.particles;
    if constexpr (Deforms)
      if (fault_ == SolverFault::deformation_transpose) held_deformation_ = P.deformation_gradient;
    update();
    if constexpr (Deforms) {
      if (fault_ == SolverFault::deformation_transpose) transpose_deformation_increments(P, held_deformation_);
      if (fault_ == SolverFault::frozen_volume) P.volume = P.reference_volume;
    }
  }

  // The constitutive update, after the locking remedy when the run has it,
  // then the bulk viscosity of the step's dilatation when it has that.
  void update_stress_of_particles(double dt) {
    const StageClock clock(stage_times_.stress);
    Particles& P = model_.particles;
    if (dilatation_ == Dilatation::cell_averaged) average_cell_dilatation<Shape::geometry>(model_.grid, P, volume_sums_);
    if (dilatation_ == Dilatation::node_smoothed)
      smooth_node_dilatation(bind(P), P, volume_sums_, model_.grid.node_count());
    for_each_material([&](const Material& m, std::size_t begin, std::size_t end) {
      update_stress<Shape::geometry>(m, P, begin, end);
    });
    if (fault_ == SolverFault::kirchhoff_stress) stress_times_dilatation(P);
    if (fault_ == SolverFault::no_hoop_stress) std::fill(P.hoop_stress.begin(), P.hoop_stress.end(), 0.0);
    if (viscous()) {
      viscous_ratio_ = 0.0;
      for_each_material([&](const Material& m, std::size_t begin, std::size_t end) {
        const ViscousStep v = add_bulk_viscosity(bind(P), P, volume_before_, m.p_wave_modulus(), model_.grid.h,
                                                 viscosity_linear_, viscosity_quadratic_, dt, begin, end);
        ledger_.damping -= v.dissipated;
        viscous_ratio_ = std::max(viscous_ratio_, v.max_ratio);
      });
    }
    // lagged-stress: the stress just updated is held back for one step, and
    // the forces of the next step weigh the one before it.
    if (fault_ == SolverFault::lagged_stress) P.stress.swap(held_stress_);
  }

  // Calls f(material, begin, end) for each material and the particles it
  // holds: all of them, or [0, from) and [from, n) with a second material.
  template <class F>
  void for_each_material(F&& f) const {
    const std::size_t n = model_.particles.size();
    const std::size_t split = second_material_ ? second_material_from_ : n;
    f(material_, 0, split);
    if (second_material_) f(*second_material_, split, n);
  }

  bool viscous() const { return viscosity_linear_ > 0.0 || viscosity_quadratic_ > 0.0; }

  // The volumes before a deformation update, from which the bulk viscosity
  // takes the step's dilatation.
  void remember_volumes() {
    if (viscous()) volume_before_ = model_.particles.volume;
  }

  // a_g and v_g^L from the node sums (eqs. 1.71-1.72), with the scene's damping
  // (eq. 1.65), then the walls, the scene's prescribed node motion and its
  // contact. (The velocity-only passes of USF and MUSL see contact through
  // the particle velocities it has corrected.)
  void advance_grid(const Shape& shape, double t, double dt, double kick) {
    const StageClock clock(stage_times_.grid);
    update_grid_motion(fields_, kick);
    if (damping_ > 0.0) damp_grid_motion(fields_, damping_, kick);
    walls(fields_);
    if (!constraints_.empty()) {
      reactions_ = apply_constraints(constraints_, t, dt, kick, fields_);
      book_constraint_work(t, dt);
    }
    if (rest_) rest_->apply(fields_, kick);
    if (contact_) {
      apply_rigid_contact(*contact_, shape, model_.particles, model_.grid, fields_, t, dt, kick, contact_scratch_,
                          contact_forces_);
      for (std::size_t i = 0; i < contact_forces_.node_force.size(); ++i)
        if (contact_forces_.node_force[i].x() != 0.0 || contact_forces_.node_force[i].y() != 0.0)
          ledger_.contact += dt * contact_forces_.node_force[i].dot(fields_.velocity[i]);
    }
    if (damping_ > 0.0) ledger_.damping += dt * damping_power(model_.grid, fields_, damping_, fixed_components_);
  }

  // Each constraint's reaction does work along its prescribed increment.
  void book_constraint_work(double t, double dt) {
    for (std::size_t k = 0; k < constraints_.size(); ++k)
      ledger_.constraints +=
          reactions_[k] * (constraints_[k].displacement(t + dt) - constraints_[k].displacement(t));
  }

  // The body force's work over the step, sum m b . v dt with v the velocity
  // the particles carry over it.
  void book_body_work(double dt) {
    if (!body_force_) return;
    const Particles& P = model_.particles;
    const std::size_t n = P.size();
    ThreadOrderedSums<1> work;
#pragma omp parallel
    {
      double own = 0.0;
#pragma omp for schedule(static)
      for (std::size_t p = 0; p < n; ++p) own += P.mass[p] * P.body_force[p].dot(P.velocity[p]);
      work.keep({own});
    }
    ledger_.body += dt * work.total()[0];
  }

  void evaluate_body_force(double t) {
    const auto start = std::chrono::steady_clock::now();
    Particles& P = model_.particles;
    if (fault_ == SolverFault::lagged_force_time) {
      const double now = t;
      t = std::min(t, force_time_);
      force_time_ = now;
    }
    if (fault_ == SolverFault::force_at_current_position) {
      // The force's points placed at x_p for this evaluation (and back).
      P.reference_position.swap(P.position);
      body_force_->prepare(P);
      P.reference_position.swap(P.position);
    }
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

  Scheme scheme_;
  bool apic_;  // velocity_transfer = apic
  SolverFault fault_;  // none, but in a fault-injection test (faults.hpp)
  double gradient_scale_;  // 1, but under cpdi-gradient
  Dilatation dilatation_;
  double split_length_;  // CPDI domains longer than this are split in two (split.hpp); 0: never
  double open_cos_;  // CPDI domains whose sides meet at |cos| above this are turned (domain_angle.hpp); 1: never
  static constexpr bool kTurnedDomains = [] {
    if constexpr (requires { Shape::turned_domains; }) return Shape::turned_domains;
    return false;
  }();
  static constexpr bool kCornerDomains = [] {
    if constexpr (requires { Shape::corner_domains; }) return Shape::corner_domains;
    return false;
  }();
  // The time of the step whose map prepare_step made, or kNotMapped.
  static constexpr double kNotMapped = -std::numeric_limits<double>::infinity();
  double mapped_at_ = kNotMapped;
  // USL: each particle's stencil from the map, read back by the update (stored_stencils.hpp)
  std::vector<Stencil<Shape::stencil_size>> stencils_;
  double viscosity_linear_, viscosity_quadratic_;  // bulk viscosity C0, C1 (add_bulk_viscosity); 0: none
  double viscous_ratio_ = 0.0;                     // its damping ratio in the last step
  std::vector<double> volume_before_;              // with bulk viscosity: V_p before the deformation update
  std::vector<std::vector<double>> volume_sums_;  // dilatation remedies: per-thread cell or node volume sums
  Material material_;
  std::optional<Material> second_material_;  // of particles [second_material_from_, n); absent: one material
  std::size_t second_material_from_;
  std::shared_ptr<BodyForce> body_force_;
  std::vector<NodeConstraint> constraints_;
  std::optional<RestPoints> rest_;  // the scene's rest points (rest_points.hpp); absent without them
  double damping_;
  std::vector<unsigned char> fixed_components_;  // with damping: the components constraints prescribe
  std::optional<RigidBody> contact_;
  ContactScratch contact_scratch_;
  std::size_t second_;                  // first particle of the second body; 0: one body
  GridFields fields_b_;                 // the second body's grid field
  std::vector<Vec2> gradient_a_, gradient_b_;  // mass gradients, eq. 1.107
  std::vector<std::vector<Vec2>> gradient_buffers_;
  ScatterBuffers buffers_;
  std::vector<double> node_motion_;  // grid_to_particles' packed a_g and v_g^L
  std::vector<Vec2> next_position_;  // MUSL only: x_{n+1} while x_n still sets the weights
  std::vector<std::size_t> split_parents_;  // split_long_domains: the particles a split cut in the last step
  std::vector<Vec2> next_corner_;    // MUSL with corner domains: the corners at t_{n+1}, likewise
  std::vector<Mat2> step_start_deformation_;  // USF with CPDI only: F_n, which sets the domains
  std::vector<Vec2> tracer_reference_;         // total Lagrangian: where each tracer reads the grid
  // Held for the faults only (faults.hpp): F before an update
  // (deformation-transpose), the stress one update behind (lagged-stress), the
  // time of the last force evaluation (lagged-force-time) and the first
  // scan's signal speed (frozen-time-step).
  std::vector<Mat2> held_deformation_;
  std::vector<Mat2> held_stress_;
  double force_time_ = std::numeric_limits<double>::infinity();
  mutable double first_signal_speed_ = 0.0;
};

template <class Shape>
std::unique_ptr<Stepper> make_for_shape(Model model, const SolverOptions& o, const MaterialModel& material,
                                        SceneStages stages) {
  return std::visit(
      [&](const auto& m) -> std::unique_ptr<Stepper> {
        using Material = std::decay_t<decltype(m)>;
        std::optional<Material> second;
        if (stages.second_material) {
          const Material* same = std::get_if<Material>(&*stages.second_material);
          if (!same) throw std::invalid_argument("the second material must be a model of the same kind as the first");
          second = *same;
        }
        const StepSettings settings = step_settings(o, model.grid.h);
        return std::make_unique<ExplicitStepper<Shape, Material>>(std::move(model), settings, m, std::move(second),
                                                                 std::move(stages));
      },
      material);
}

template <Geometry G>
std::unique_ptr<Stepper> make_for_geometry(Model model, const SolverOptions& o, const MaterialModel& material,
                                           SceneStages stages) {
  if constexpr (G == Geometry::plane_strain)
    if (o.formulation == Formulation::total) switch (o.method) {
        case Method::gimp: return make_for_shape<TotalLagrangianGimpShape>(std::move(model), o, material, std::move(stages));
        case Method::cpdi: return make_for_shape<TotalLagrangianCpdiShape>(std::move(model), o, material, std::move(stages));
        case Method::cpdi_exact:
          return make_for_shape<TotalLagrangianCpdiExactShape>(std::move(model), o, material, std::move(stages));
        case Method::linear:
          return make_for_shape<TotalLagrangianLinearShape>(std::move(model), o, material, std::move(stages));
        case Method::bspline:
          return make_for_shape<TotalLagrangianShapeT<BsplineShape>>(std::move(model), o, material, std::move(stages));
        case Method::bspline_cubic:
          return make_for_shape<TotalLagrangianShapeT<CubicBsplineShape>>(std::move(model), o, material,
                                                                          std::move(stages));
      }
  switch (o.method) {
    case Method::linear: return make_for_shape<LinearShapeT<G>>(std::move(model), o, material, std::move(stages));
    case Method::gimp: return make_for_shape<GimpShapeT<G>>(std::move(model), o, material, std::move(stages));
    case Method::cpdi:
      if constexpr (G == Geometry::plane_strain) {
        if (o.min_domain_angle > 0.0)
          return make_for_shape<CpdiShapeT<G, CpdiForm::turned>>(std::move(model), o, material, std::move(stages));
        if (o.cpdi_domain == CpdiDomain::corners)
          return make_for_shape<CpdiShapeT<G, CpdiForm::corners>>(std::move(model), o, material, std::move(stages));
      }
      return make_for_shape<CpdiShapeT<G>>(std::move(model), o, material, std::move(stages));
    case Method::cpdi_exact:
      if constexpr (G == Geometry::plane_strain)
        if (o.cpdi_domain == CpdiDomain::corners)
          return make_for_shape<CpdiExactShapeT<G, true>>(std::move(model), o, material, std::move(stages));
      return make_for_shape<CpdiExactShapeT<G>>(std::move(model), o, material, std::move(stages));
    case Method::bspline:
    case Method::bspline_cubic:
      if constexpr (G == Geometry::plane_strain) {
        if (o.method == Method::bspline)
          return make_for_shape<BsplineShape>(std::move(model), o, material, std::move(stages));
        return make_for_shape<CubicBsplineShape>(std::move(model), o, material, std::move(stages));
      } else {
        throw std::logic_error("B-splines in r-z (make_stepper refuses them)");
      }
  }
  throw std::logic_error("unknown method");
}

}  // namespace

void check_domain_outlines(const Particles& P, Method method) {
  if (P.domain_first.empty() && P.domain_vertex.empty()) return;
  if (method != Method::cpdi_exact)
    throw std::invalid_argument(fmt::format("particle outlines serve method cpdi-exact only, not {}", to_string(method)));
  if (P.domain_first.size() != P.size() + 1 || P.domain_first.front() != 0 ||
      P.domain_first.back() != P.domain_vertex.size())
    throw std::invalid_argument("particle outlines need one start per particle and an end");
  for (std::size_t p = 0; p < P.size(); ++p) {
    const std::uint32_t count = P.domain_first[p + 1] - P.domain_first[p];
    if (P.domain_first[p + 1] < P.domain_first[p] || (count != 0 && count < 3) ||
        count > std::uint32_t(CpdiExactShape::kMaxOutline))
      throw std::invalid_argument(fmt::format("particle {} has an outline of {} points; an outline has 3 to {}", p,
                                              int(P.domain_first[p + 1]) - int(P.domain_first[p]),
                                              CpdiExactShape::kMaxOutline));
  }
}

std::unique_ptr<Stepper> make_stepper(Model model, const SolverOptions& options,
                                      const MaterialModel& material,
                                      std::shared_ptr<BodyForce> body_force) {
  SceneStages stages;
  stages.body_force = std::move(body_force);
  return make_stepper(std::move(model), options, material, std::move(stages));
}

std::unique_ptr<Stepper> make_stepper(Model model, const SolverOptions& options,
                                      const MaterialModel& material, SceneStages stages) {
  const std::size_t n = model.particles.size();
  if (!(stages.damping >= 0.0)) throw std::invalid_argument("damping must be zero or positive");
  if (!(options.split_domains_beyond >= 0.0))
    throw std::invalid_argument("split_domains_beyond must be zero (never) or a positive number of cells");
  const bool bspline = options.method == Method::bspline || options.method == Method::bspline_cubic;
  if (bspline && options.geometry != Geometry::plane_strain)
    throw std::invalid_argument(fmt::format("method {} is plane strain only: in r-z a particle near the axis would "
                                            "weigh nodes at r < 0", to_string(options.method)));
  if (options.split_domains_beyond > 0.0) {
    if (options.method != Method::cpdi && !(options.method == Method::cpdi_exact && options.cpdi_domain == CpdiDomain::corners))
      throw std::invalid_argument("split_domains_beyond is for method cpdi, or cpdi-exact with cpdi_domain = corners "
                                  "(a split halves a parallelogram or a quadrilateral, not an outline)");
    if (options.geometry != Geometry::plane_strain)
      throw std::invalid_argument("split_domains_beyond is plane strain only");
    if (stages.second_body > 0) throw std::invalid_argument("split_domains_beyond serves one body only");
  }
  // Below a right angle: the rectangle's orientation is the principal axes',
  // which a square domain does not have (round-off would pick them).
  if (!(options.min_domain_angle >= 0.0 && options.min_domain_angle < 90.0))
    throw std::invalid_argument("min_domain_angle is an angle in degrees from 0 (never) to below 90");
  if (options.min_domain_angle > 0.0) {
    if (options.method != Method::cpdi) throw std::invalid_argument("min_domain_angle is for method cpdi only");
    if (options.geometry != Geometry::plane_strain)
      throw std::invalid_argument("min_domain_angle is plane strain only (in r-z the domain's moments carry "
                                  "the weight r)");
    if (options.formulation == Formulation::total)
      throw std::invalid_argument("min_domain_angle serves the updated formulation: total Lagrangian domains "
                                  "never deform");
  }
  if (options.cpdi_domain == CpdiDomain::corners) {
    if (options.method != Method::cpdi && options.method != Method::cpdi_exact)
      throw std::invalid_argument("cpdi_domain = corners is for methods cpdi and cpdi-exact");
    if (options.geometry != Geometry::plane_strain)
      throw std::invalid_argument("cpdi_domain = corners is plane strain only");
    if (options.formulation == Formulation::total)
      throw std::invalid_argument("cpdi_domain = corners serves the updated formulation: total Lagrangian domains "
                                  "never deform");
    if (options.min_domain_angle > 0.0)
      throw std::invalid_argument("min_domain_angle turns parallelograms; corner domains (cpdi_domain = corners) "
                                  "keep the quadrilateral their corners make");
    if (stages.second_body > 0)
      throw std::invalid_argument("cpdi_domain = corners serves one body (each body's corners would read its own "
                                  "grid field)");
  }
  if (options.formulation == Formulation::total) {
    // What the reference grid cannot do yet, or does not need.
    if (options.split_domains_beyond > 0.0)
      throw std::invalid_argument("split_domains_beyond serves the updated formulation: total Lagrangian domains "
                                  "never deform");
    if (options.geometry != Geometry::plane_strain)
      throw std::invalid_argument("the total Lagrangian formulation is plane strain only");
    if (stages.contact || stages.second_body > 0)
      throw std::invalid_argument("the total Lagrangian formulation has no contact: its grid moves with one body");
    if (options.dilatation == Dilatation::cell_averaged)
      throw std::invalid_argument("the total Lagrangian formulation takes dilatation = particle or node-smoothed "
                                  "(cell-averaged bins particles by their current cell)");
  }
  if (!(options.bulk_viscosity_linear >= 0.0 && options.bulk_viscosity_quadratic >= 0.0))
    throw std::invalid_argument("the bulk viscosity coefficients must be zero (none) or positive");
  if (options.velocity_transfer == VelocityTransfer::apic) {
    // The affine field is x_g - x_p in the current configuration; the total
    // formulation weighs reference positions, and in r-z the weights are not
    // shown to reproduce linear fields.
    if (options.formulation == Formulation::total)
      throw std::invalid_argument("velocity_transfer = apic serves the updated formulation (the total formulation "
                                  "weighs the particles at their reference positions)");
    if (options.geometry != Geometry::plane_strain)
      throw std::invalid_argument("velocity_transfer = apic is plane strain only");
  }
  if (stages.contact && !stages.contact->displacement)
    throw std::invalid_argument("a contact master needs its displacement d(t)");
  if (stages.second_material) {
    if (stages.second_material_from == 0 || stages.second_material_from >= n)
      throw std::invalid_argument("each of the two materials must hold particles: 0 < second_material_from < n");
    if (options.split_domains_beyond > 0.0)
      throw std::invalid_argument("split_domains_beyond serves one material only (halves are appended at the end)");
  }
  if (stages.second_body > 0) {
    if (stages.second_body >= n) throw std::invalid_argument("the second body holds no particle");
    if (options.scheme != Scheme::usl) throw std::invalid_argument("two bodies in contact step with usl only");
    if (stages.contact) throw std::invalid_argument("two bodies in contact cannot also touch a rigid master");
    if (!stages.rest_points.empty())
      throw std::invalid_argument("rest points serve one body (each body's grid field would need its own)");
  }
  for (const NodeConstraint& c : stages.constraints) {
    if (c.axis != 0 && c.axis != 1) throw std::invalid_argument("a node constraint's axis is 0 (x) or 1 (y)");
    if (!c.displacement) throw std::invalid_argument("a node constraint needs its displacement u(t)");
    for (std::size_t node : c.nodes)
      if (node >= model.grid.node_count())
        throw std::invalid_argument(fmt::format("a node constraint names node {}, beyond the grid's {} nodes", node,
                                                model.grid.node_count()));
  }
  if (n == 0) throw std::invalid_argument("the scene seeded no particles");
  if (options.method != Method::linear && !bspline && model.particles.half_size.size() != n)
    throw std::invalid_argument(fmt::format("method {} needs a particle domain (half_size) for every particle",
                                            to_string(options.method)));
  check_domain_outlines(model.particles, options.method);
  if (options.cpdi_domain == CpdiDomain::corners && !model.particles.domain_first.empty())
    throw std::invalid_argument("corner domains replace particle outlines: seed them without outlines (the corners "
                                "start from each particle's parallelogram)");
  if (bspline) {
    auto check = [&](const auto shape) {
      for (std::size_t p = 0; p < n; ++p)
        if (!shape.clear_of_walls(p))
          throw std::invalid_argument(fmt::format(
              "method {}: the particle at ({:.6g}, {:.6g}) lies within {:g} cells (h = {:.6g}) of a wall, where its "
              "support would reach the mirrored ghost nodes (shape/bspline.hpp); keep the body that far from the "
              "walls, or take another method",
              to_string(options.method), model.particles.position[p].x(), model.particles.position[p].y(),
              shape.wall_clearance, model.grid.h));
    };
    if (options.method == Method::bspline)
      check(BsplineShape::bind(model.grid, model.particles));
    else
      check(CubicBsplineShape::bind(model.grid, model.particles));
  }
  if (options.geometry == Geometry::axisymmetric) {
    if (model.particles.hoop_stretch.size() != n || model.particles.hoop_stress.size() != n)
      throw std::invalid_argument("an axisymmetric run needs the hoop stretch and hoop stress of every particle");
    for (std::size_t p = 0; p < n; ++p)
      if (!(model.particles.position[p].x() > 0.0))
        throw std::invalid_argument(fmt::format("an axisymmetric run needs every particle off the axis (r > 0); "
                                                "particle {} is at r = {}", p, model.particles.position[p].x()));
    if (model.grid.wall_lower().x() != 0.0)
      throw std::invalid_argument("an axisymmetric grid has its left wall on the axis r = 0");
    return make_for_geometry<Geometry::axisymmetric>(std::move(model), options, material, std::move(stages));
  }
  return make_for_geometry<Geometry::plane_strain>(std::move(model), options, material, std::move(stages));
}

}  // namespace mpmvv