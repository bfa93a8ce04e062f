// A case of a scene with an exact solution: the body seeded in the exact
// state at t = 0, the solver stages the scene names, and, as the run goes,
// the probes, the error norms and the monitors of its health, written to the
// results file at its end. What is particular to a scene is its SceneSetup
// (tools/app/scenes/); everything here is shared.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <fmt/format.h>

#include "coverage.hpp"
#include "external_case.hpp"
#include "monitor_log.hpp"
#include "norms.hpp"
#include "probes.hpp"
#include "restart_file.hpp"
#include "results_file.hpp"
#include "seeding.hpp"
#include "snapshots.hpp"
#include "solver/explicit_stepper.hpp"
#include "setup.hpp"
#ifdef MPMVV_HAVE_SUNDIALS
#include "solver/implicit/static_stepper.hpp"
#endif

namespace mpmvv::app {

namespace {

constexpr double kProbeRoundoff = 1e-12;   // relative: rounding in a probe point the scene placed

class Case final : public SceneCase, private RunObserver {
 public:
  Case(const Config& config, const SceneType& type)
      : config_(config), setup_(type.setup(config)), options_(solver_options(config)),
        loop_(time_loop_options(config)), probes_(setup_) {
    options_.geometry = setup_.geometry;
    if (setup_.run_refused) config_.reject(setup_.run_refused->key, setup_.run_refused->why);
    exact_seeding_ = config_.text("seeding") == "exact";
    if (implicit() && config_.integer("stable_step_iterations") > 0)
      config_.reject("stable_step_iterations",
                     "measures the stable step of explicit runs; solver = \"implicit\" takes load steps");
#ifdef MPMVV_HAVE_CGAL
    if (exact_seeding_ && !setup_.body) throw ConfigError("this scene has no exact body: use seeding = \"centre\"");
#endif
    // A probe must be a material point of the body. A point the scene placed
    // on a rim (a line's end at the outer radius) can land an ulp outside it
    // by rounding: one within kProbeRoundoff of the body (relative to its
    // distance from the origin and the cell size) is on it.
    const auto on_body = [this](const Vec2& X) {
      if (setup_.contains(X)) return true;
      const double nudge = kProbeRoundoff * (X.norm() + setup_.grid.h);
      for (const Vec2& d : {Vec2(nudge, 0.0), Vec2(-nudge, 0.0), Vec2(0.0, nudge), Vec2(0.0, -nudge)})
        if (setup_.contains(X + d)) return true;
      return false;
    };
    for (const ProbeLine& line : setup_.lines)
      for (const Vec2& X : line.reference)
        if (!on_body(X))
          throw ConfigError(fmt::format("probe line '{}' has the point ({}, {}) outside the body", line.name,
                                        X.x(), X.y()));
    for (const ProbePoint& point : setup_.points)
      if (!on_body(point.reference))
        throw ConfigError(fmt::format("probe point '{}' at ({}, {}) lies outside the body", point.name,
                                      point.reference.x(), point.reference.y()));
  }

  void inject(Fault fault) override {
    fault_ = fault;
    options_.fault = fault.in_solver;
  }

  RunOutcome run(const ProgressSink& progress, const RestartPlan& restart) override {
    refuse_what_cannot_fit(setup_, config_);
    Model model;
    model.grid = setup_.grid;
    // Exact CPDI domains follow a clipped piece's outline, arcs in chords of
    // a quarter of the particle spacing (the chord's sagitta, spacing^2 /
    // (128 R), is far below what a piece's area can tell). Corner domains
    // start from each particle's parallelogram (domain_corners.hpp).
    const bool outlines =
        options_.method == Method::cpdi_exact && options_.cpdi_domain != CpdiDomain::corners && exact_seeding_;
    seeded_ = seed_particles(setup_,
                             {int(config_.integer("particles_per_direction")), exact_seeding_,
                              options_.method != Method::linear, outlines, fault_ == Fault::exact_seeding_volume},
                             model.particles);
    if (model.particles.size() == 0)
      throw ConfigError(fmt::format("the body holds no particle centre at cells = {}: use more cells",
                                    config_.integer("cells")));
    probes_.seed_tracers(model.tracers);
    start_error_table();
    SceneStages stages;
    if (setup_.stages) stages = setup_.stages(model.particles, model.grid);
    if (setup_.second_material) {
      stages.second_material = setup_.second_material;
      stages.second_material_from = seeded_.first_material_count;
    }
    if (!setup_.force_free && fault_ != Fault::no_body_force) {
      std::shared_ptr<mms::ForceField> field = setup_.fast_body_force;
      if (!field) field = mms::derived_force_field(setup_.solution);
      stages.body_force = std::make_shared<mms::ManufacturedBodyForce>(field, force_quadrature(), setup_.geometry);
    }
    if (implicit()) {
#ifdef MPMVV_HAVE_SUNDIALS
      loop_.fixed_step = load_step();
      StaticOptions static_options;
      static_options.tolerance = config_.real("newton_tolerance");
      stepper_ = make_static_stepper(std::move(model), options_, setup_.material, std::move(stages), static_options);
#else
      throw ConfigError("solver = \"implicit\" needs SUNDIALS (built without it: MPMVV_WITH_SUNDIALS=OFF)");
#endif
    } else {
      stepper_ = make_stepper(std::move(model), options_, setup_.material, std::move(stages));
    }
    Checkpoints checkpoints;
    LoopState resumed;
    const ScenePersist own = [this](StateArchive& a) { persist(a); };
    if (!restart.path.empty()) {
      if (!stepper_->restartable())
        throw ConfigError("a restart file (--checkpoint-every, --pause-at, --resume) holds the state of explicit "
                          "runs only: solver = \"implicit\" keeps its own");
      if (restart.resume) {
        read_restart(restart.path, resumed, *stepper_, own);
        checkpoints.resume = &resumed;
      }
      checkpoints.every_seconds = restart.every_seconds;
      checkpoints.pause_at = restart.pause_at;
      checkpoints.save = [this, &restart, &own](const LoopState& state) { save_restart(restart, state, *stepper_, own); };
    }
    outcome_ = run_time_loop(*stepper_, loop_, *this, progress, 1.0, checkpoints);
    return outcome_;
  }

  // What the case has recorded (the rest is rebuilt as the case is set up:
  // seeding, tracers, probes).
  void persist(StateArchive& a) {
    probes_.persist(a);
    monitor_log_.persist(a);
    coverage_.persist(a);
    a.field("rule_step", rule_step_);
    a.field("errors", errors_);
    a.field("integrated", integrated_);
    snapshots_.persist(a);
    bool settling = settling_.has_value();
    a.field("settling", settling);
    if (a.reads()) {
      settling_.reset();
      if (settling) settling_.emplace(*setup_.settling, loop_.end_time, !implicit());
    }
    if (settling_) a.field("settling_watch", *settling_);
  }

  bool implicit() const { return config_.has("solver") && config_.text("solver") == "implicit"; }
  // An implicit run's step: the load's ramp (to smooth_until, or the end) in load_steps.
  double load_step() const {
    const double ramp = std::isfinite(setup_.smooth_until) ? setup_.smooth_until : loop_.end_time;
    return ramp / double(config_.integer("load_steps"));
  }

  mms::ForceQuadrature force_quadrature() const {
    return config_.has("body_force_quadrature") && config_.text("body_force_quadrature") == "domain"
               ? mms::ForceQuadrature::domain
               : mms::ForceQuadrature::centroid;
  }

  double cell_size() const override { return setup_.grid.h; }
  Geometry geometry() const override { return setup_.geometry; }
  std::string body_force_kind() const override {
    if (setup_.force_free) return setup_.loading.empty() ? "none" : "none; " + setup_.loading;
    std::string kind = setup_.fast_body_force ? "closed form" : "derived";
    if (force_quadrature() == mms::ForceQuadrature::domain) kind += ", mean over each particle's domain";
    return setup_.loading.empty() ? kind : kind + "; " + setup_.loading;
  }
  Measurements measurements() const override {
    if (!stepper_) return {};
    Measurements m;
    if (setup_.measure) m = setup_.measure(probes_.record(*stepper_));
    for (const auto& s : stepper_->statistics()) m.push_back(s);
    if (settling_) {
      const Settling s = settling_->measure(outcome_.time_reached, *stepper_);
      m.push_back({"settling_displacement", s.displacement});
      m.push_back({"settling_strain", s.strain});
    }
    if (!monitor_log_.rows().empty()) {
      // The energy balance at the last output (MonitorLog::record).
      m.push_back({"energy_created", monitor_log_.rows().back().created});
      m.push_back({"energy_scale", monitor_log_.energy_scale()});
    }
    return m;
  }
  std::string seeding() const override { return exact_seeding_ ? "exact" : "centre"; }
  double particle_volume() const override { return seeded_.particle_volume; }
  double body_volume() const override { return exact_body_volume(setup_); }
  std::size_t particle_count() const override { return stepper_ ? stepper_->model().particles.size() : 0; }
  std::optional<WorkEstimate> estimate() const override {
    // The particle lattice over the walls, sampled at most 1024 points an axis
    // (a 1200-cell case has 9,600 particles an axis), in the body or not.
    const GridGeometry& g = setup_.grid;
    const Vec2 lower = g.wall_lower(), extent = g.wall_upper() - g.wall_lower();
    const double spacing = g.h / double(config_.integer("particles_per_direction"));
    const double across_x = extent.x() / spacing, across_y = extent.y() / spacing;
    const int nx = std::clamp(int(std::lround(across_x)), 1, 1024), ny = std::clamp(int(std::lround(across_y)), 1, 1024);
    std::size_t inside = 0;
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        inside += setup_.contains(lower + Vec2((i + 0.5) / nx * extent.x(), (j + 0.5) / ny * extent.y()));
    WorkEstimate w;
    w.particles = std::size_t(std::llround(double(inside) / (double(nx) * ny) * across_x * across_y));
    // A fixed step (an implicit run's load steps) counts itself; the CFL
    // step is taken at rest.
    const double c0 = std::sqrt(p_wave_modulus(setup_.material) / config_.real("density"));
    const double dt = implicit()               ? load_step()
                      : loop_.fixed_step > 0.0 ? loop_.fixed_step
                                               : loop_.cfl * g.h / c0;
    w.steps = (long long)std::ceil(loop_.end_time / dt - 1e-9);
    w.implicit = implicit();
    return w;
  }
  const ErrorTable& errors() const override { return errors_; }

  RunHealth health() const override {
    return monitor_log_.health(errors_, {config_.real("health_J_factor"), config_.real("health_energy_loss_factor"),
                                         setup_.exact_motion});
  }

  std::string error_description() const override { return norm_definitions(); }

  void write_results(h5::Group& root) const override {
    const Particles& P = stepper_->model().particles;
    write_particles(root, P);
    write_particle_index(root, std::max(P.size(), snapshots_.largest_count()));
    snapshots_.write(root);
    h5::Group probes = root.create_group("probes");
    write_probes(probes, probes_);
    if (setup_.write_extra) setup_.write_extra(probes);
    write_monitors(probes, monitor_log_, config_.integer("stable_step_iterations") > 0);
    if (coverage_.on()) write_coverage(probes, coverage_, setup_.grid.h);
    if (settling_ && stepper_)
      write_settling(root, *settling_, settling_->measure(outcome_.time_reached, *stepper_), outcome_.time_reached,
                     errors_);
  }

  std::optional<double> exact_signal_fraction(const std::string& norm, double time) const override {
    return app::exact_signal_fraction(setup_, loop_, norm, time);
  }
  std::vector<std::string> possible_error_columns() const override { return error_columns(setup_); }

 private:
  // The columns of /errors: each line's L1, the particle norms with an exact
  // motion, the scene's own.
  void start_error_table() {
    errors_ = ErrorTable{};
    for (const std::string& name : error_columns(setup_)) errors_.add_column(name, error_unit(name, setup_.lines));
  }

  // The energy at the start, for the balance (monitors.hpp), and the first
  // point of the time-integrated error.
  void initial(const Stepper& s) override {
    integrated_ = {};
    if (setup_.exact_motion) {
      const DisplacementSums d = displacement_sums(s.model().particles, *setup_.solution, 0.0);
      integrated_.add(0.0, d.l2, d.exact2);
    }
    monitor_log_.start(s);
    // The lattice of the coverage monitor, over the domains as seeded.
    const std::int64_t samples = config_.integer("coverage_samples");
    const double particle_spacing = setup_.grid.h / double(config_.integer("particles_per_direction"));
    if (setup_.exact_motion && samples > 0)
      coverage_.start(s.domain_polygons(), particle_spacing / double(samples), particle_spacing);
    else
      coverage_ = {};
    settling_.reset();
    if (setup_.settling) {
      settling_.emplace(*setup_.settling, loop_.end_time, !implicit());
      if (settling_->observe(0.0, s.model().particles))
        settling_->keep_norms(settling_norms(setup_, errors_, probes_, 0.0, s));
    }
  }

  std::pair<std::string, std::string> stop() const override { return monitor_log_.stop(); }

  void step_rule(double dt) override { rule_step_ = dt; }

  void after_step(double t, const Stepper& s) override {
    if (setup_.exact_motion) monitor_log_.sample_motion(t, s.model().particles, *setup_.solution);
    if (settling_ && settling_->observe(t, s.model().particles))
      settling_->keep_norms(settling_norms(setup_, errors_, probes_, t, s));
    probes_.after_step(t, s);
  }

  void at_output(std::size_t, double t, const Stepper& s) override {
    monitor_log_.record(t, s, int(config_.integer("stable_step_iterations")), rule_step_,
                        config_.real("energy_blowup_factor"));
    errors_.time.push_back(t);
    if (coverage_.on()) coverage_.record(t, s.domain_polygons(), s.model().particles, *setup_.solution);
    if (config_.text("particle_fields") == "outputs")
      snapshots_.record(t, s.model().particles, setup_.exact_motion ? setup_.solution.get() : nullptr,
                        s.model().tracers);
    const std::vector<double> line_l1 = probes_.at_output(t, s.model().tracers);
    for (std::size_t k = 0; k < line_l1.size(); ++k) errors_.columns[k].second.push_back(line_l1[k]);
    // Volume-weighted errors over all particles (norms.hpp).
    std::size_t column = setup_.lines.size();
    if (setup_.exact_motion) {
      const Particles& P = s.model().particles;
      double spin = 0.0;
      for (double value :
           particle_norms(P, *setup_.solution, setup_.geometry, t, integrated_, monitor_log_.j_ratio(), spin))
        errors_.columns[column++].second.push_back(value);
      monitor_log_.record_J_ratio(P);
      if (setup_.geometry == Geometry::plane_strain) monitor_log_.set_exact_angular_momentum(spin);
    }
    if (!setup_.extra_error_names.empty()) {
      const std::vector<double> extra = setup_.extra_errors(t, probes_.record(s));
      if (extra.size() != setup_.extra_error_names.size())
        throw std::logic_error("a scene's extra errors do not match their names");
      for (std::size_t k = 0; k < extra.size(); ++k) errors_.columns[column + k].second.push_back(extra[k]);
    }
  }

  Config config_;
  Fault fault_;
  bool exact_seeding_ = false;
  Seeded seeded_;
  SceneSetup setup_;
  SolverOptions options_;
  TimeLoopOptions loop_;
  std::unique_ptr<Stepper> stepper_;
  RunOutcome outcome_;

  ProbeRecorder probes_;
  ParticleSnapshots snapshots_;  // with particle_fields = "outputs"
  MonitorLog monitor_log_;
  DomainCoverage coverage_;  // with domains and an exact motion (coverage_samples > 0)
  double rule_step_ = std::numeric_limits<double>::quiet_NaN();  // the time-step rule's last step
  ErrorTable errors_;
  TimeIntegral integrated_;
  std::optional<SettlingWatch> settling_;  // a static scene's distance from its static state at the end
};

}  // namespace

std::unique_ptr<SceneCase> SceneType::build(const Config& config) const {
  if (const std::optional<ExternalProgram> program = external_program(config))
    return make_external_case(config, *this, *program);
  return std::make_unique<Case>(config, *this);
}

}  // namespace mpmvv::app
