#include "mms_scene.hpp"

#include "fault.hpp"
#include "solver/io/state_archive.hpp"
#include "solver/parallel.hpp"
#ifdef MPMVV_HAVE_SUNDIALS
#include "solver/explicit_stepper.hpp"
#include "solver/implicit/static_stepper.hpp"
#endif

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>

#ifdef MPMVV_HAVE_FFTW
#include "analytic/fft.hpp"
#endif

namespace mpmvv::app {

namespace fs = std::filesystem;

const char* to_string(ProbeQuantity q) {
  switch (q) {
    case ProbeQuantity::angular_displacement: return "angular_displacement";
    case ProbeQuantity::radial_displacement: return "radial_displacement";
    case ProbeQuantity::displacement_x: return "displacement_x";
    case ProbeQuantity::displacement_y: return "displacement_y";
  }
  return "?";
}

KeySpec seeding_key() {
  const double inf = std::numeric_limits<double>::infinity();
#ifdef MPMVV_HAVE_CGAL
  const std::vector<std::string> choices = {"exact", "centre"};
  const std::string fallback = "exact";
#else
  const std::vector<std::string> choices = {"centre"};
  const std::string fallback = "centre";
#endif
  return {"seeding", KeyKind::text, fallback,
          "exact: particles in cells the boundary cuts get the exact clipped volume and centroid (CGAL), so the body's "
          "volume is exact; centre: a particle wherever its sub-cell centre lies in the body (a staircase boundary)",
          -inf, inf, false, false, choices};
}

KeySpec force_quadrature_key() {
  const double inf = std::numeric_limits<double>::infinity();
  return {"body_force_quadrature", KeyKind::text, std::string("centroid"),
          "centroid: each particle takes the body force at its reference centroid; domain: the mean over its "
          "reference domain by 2 x 2 Gauss points (mms/force_field.hpp), which removes the centroid rule's error of "
          "order (h / particles_per_direction)^2 where the force is large against the motion it makes (a stiff "
          "solid moved slowly)",
          -inf, inf, false, false, {"centroid", "domain"}};
}

KeySpec body_force_key(const std::string& closed_form) {
  const double inf = std::numeric_limits<double>::infinity();
  return {"body_force", KeyKind::text, std::string("closed-form"),
          "closed-form: " + closed_form + " (neo-hookean only; equal to the derived force to round-off); derived: "
          "automatic differentiation of the motion and material",
          -inf, inf, false, false, {"closed-form", "derived"}};
}

const NeoHookean* closed_form_force(const Config& c, const MaterialModel& material, const std::string& closed_form) {
  if (c.text("body_force") != "closed-form") return nullptr;
  const NeoHookean* solid = std::get_if<NeoHookean>(&material);
  if (!solid)
    c.reject("body_force", fmt::format("the closed form ({}) holds for the neo-Hookean solid only; material = \"{}\" "
                                       "(from {}) needs body_force = \"derived\"",
                                       closed_form, c.text("material"), c.origin("material").source));
  return solid;
}

std::vector<KeySpec> problem_keys(std::vector<KeySpec> k, const std::vector<KeySpec>& own,
                                  const std::vector<KeySpec>& material) {
  k.insert(k.end(), own.begin(), own.end());
  k.push_back(seeding_key());
  k.insert(k.end(), material.begin(), material.end());
  return k;
}

std::vector<KeySpec> material_keys(const std::string& default_material, double lambda, double mu, double density) {
  const double inf = std::numeric_limits<double>::infinity();
  return {
      {"material", KeyKind::text, default_material,
       "neo-hookean (eq. 2.2), mooney-rivlin (eq. 2.18 with K ln J) or linear-elastic (small strain)", -inf, inf,
       false, false, {"neo-hookean", "mooney-rivlin", "linear-elastic"}},
      {"lambda", KeyKind::real, lambda, "first Lame constant, neo-hookean and linear-elastic [Pa]"},
      {"mu", KeyKind::real, mu, "shear modulus, neo-hookean and linear-elastic [Pa]", 0.0, inf, true},
      {"c1", KeyKind::real, 0.5 * mu, "C1 of mooney-rivlin [Pa] (shear modulus 2 (C1 + C2))"},
      {"c2", KeyKind::real, 0.0, "C2 of mooney-rivlin [Pa]"},
      {"bulk_modulus", KeyKind::real, lambda + 2.0 / 3.0 * mu, "K of mooney-rivlin [Pa]", 0.0, inf, true},
      {"density", KeyKind::real, density, "reference density rho_0 [kg/m^3]", 0.0, inf, true},
  };
}

MaterialModel material_from(const Config& c) {
  const std::string& m = c.text("material");
  if (m == "mooney-rivlin") {
    if (!(c.real("c1") + c.real("c2") > 0.0))
      c.reject("c1", fmt::format("c1 + c2 must be positive (a positive shear modulus); c2 = {} from {}",
                                 c.real("c2"), c.origin("c2").source));
    return MooneyRivlin{c.real("c1"), c.real("c2"), c.real("bulk_modulus")};
  }
  if (!(c.real("lambda") > -2.0 / 3.0 * c.real("mu")))
    c.reject("lambda", fmt::format("must exceed -2 mu / 3 = {:.6g} (a positive bulk modulus; mu from {})",
                                   -2.0 / 3.0 * c.real("mu"), c.origin("mu").source));
  if (m == "linear-elastic") return LinearElastic{c.real("lambda"), c.real("mu")};
  return NeoHookean{c.real("lambda"), c.real("mu")};
}

std::vector<Vec2> points_on_segment(const Vec2& a, const Vec2& b, int count) {
  std::vector<Vec2> out;
  for (int i = 0; i < count; ++i) out.push_back(a + (b - a) * (double(i) / double(count - 1)));
  return out;
}

void ProblemSetup::body_is_rectangle(const Vec2& lower, const Vec2& upper) {
  contains = [lower, upper](const Vec2& X) {
    return X.x() >= lower.x() && X.x() <= upper.x() && X.y() >= lower.y() && X.y() <= upper.y();
  };
#ifdef MPMVV_HAVE_CGAL
  body = Body::rectangle(lower, upper);
#endif
}

void ProblemSetup::body_is_annulus(double inner_radius, double outer_radius) {
  contains = [inner_radius, outer_radius](const Vec2& X) {
    const double R = X.norm();
    return R >= inner_radius && R <= outer_radius;
  };
#ifdef MPMVV_HAVE_CGAL
  body = Body::annulus(Vec2::Zero(), inner_radius, outer_radius);
#endif
}

namespace {

using std::numbers::pi;

// The quantity at a material point with current position x, reference X and
// exact current position x_exact. Angles are unwrapped about the exact value
// (the error stays far below pi).
double probe_value(ProbeQuantity q, Geometry geometry, const Vec2& x, const Vec2& X, const Vec2& x_exact) {
  switch (q) {
    case ProbeQuantity::angular_displacement: {
      const double reference = std::atan2(X.y(), X.x());
      const double exact = std::atan2(x_exact.y(), x_exact.x()) - reference;
      return exact + std::remainder(std::atan2(x.y(), x.x()) - reference - exact, 2.0 * pi);
    }
    case ProbeQuantity::radial_displacement:
      return geometry == Geometry::axisymmetric ? x.x() - X.x() : x.norm() - X.norm();
    case ProbeQuantity::displacement_x: return x.x() - X.x();
    case ProbeQuantity::displacement_y: return x.y() - X.y();
  }
  return 0.0;
}

struct LineRecord {
  std::vector<std::vector<double>> simulated, exact;  // per output time

  template <class Archive>
  void persist(Archive& a) {
    a.field("simulated", simulated);
    a.field("exact", exact);
  }
};

class MmsCase final : public SceneCase, private RunObserver {
 public:
  MmsCase(const Config& config, const MmsProblem& problem)
      : config_(config), setup_(problem.setup(config)), options_(solver_options(config)),
        loop_(time_loop_options(config)) {
    options_.geometry = setup_.geometry;
    exact_seeding_ = config_.text("seeding") == "exact";
    if (implicit() && config_.integer("stable_step_iterations") > 0)
      config_.reject("stable_step_iterations",
                     "measures the stable step of explicit runs; solver = \"implicit\" takes load steps");
#ifdef MPMVV_HAVE_CGAL
    if (exact_seeding_ && !setup_.body) throw ConfigError("this scene has no exact body: use seeding = \"centre\"");
#endif
    // A probe must be a material point of the body.
    for (const ProbeLine& line : setup_.lines)
      for (const Vec2& X : line.reference)
        if (!setup_.contains(X))
          throw ConfigError(fmt::format("probe line '{}' has the point ({}, {}) outside the body", line.name,
                                        X.x(), X.y()));
    for (const ProbePoint& point : setup_.points)
      if (!setup_.contains(point.reference))
        throw ConfigError(fmt::format("probe point '{}' at ({}, {}) lies outside the body", point.name,
                                      point.reference.x(), point.reference.y()));
  }

  void inject(Fault fault) override {
    fault_ = fault;
    options_.fault = fault.in_solver;
  }

  // The memory the case will hold, estimated before anything is allocated:
  // the particles (at most about 400 bytes each with the stencils a step
  // stores and the copies an output makes; 168-280 measured for CPDI,
  // mpmvv-bench-throughput) and the grid (the fields of GridFields, 11
  // doubles per node, and a scatter buffer of 5 doubles per node for each
  // thread). A case that cannot fit in the machine's memory is refused,
  // naming the keys that set it, rather than ending in an allocation failure.
  void refuse_what_cannot_fit() const {
    const GridGeometry& g = setup_.grid;
    double area = (g.upper() - g.origin).prod();
#ifdef MPMVV_HAVE_CGAL
    if (setup_.body) area = setup_.body->whole().area;
#endif
    const double spacing = g.h / double(config_.integer("particles_per_direction"));
    const double particles = area / (spacing * spacing);
    const double nodes = double(g.node_count());
    const int threads = max_threads();
    const double needed = 400.0 * particles + 8.0 * nodes * (11.0 + 5.0 * threads);
    const double machine = double(::sysconf(_SC_PHYS_PAGES)) * double(::sysconf(_SC_PAGESIZE));
    if (machine > 0.0 && needed > machine)
      throw ConfigError(fmt::format(
          "cells = {}, particles_per_direction = {} and threads = {} need about {:.3g} GiB ({:.3g} particles, {:.3g} "
          "grid nodes), more than this machine's {:.3g} GiB: use fewer cells, particles per direction or threads",
          config_.integer("cells"), config_.integer("particles_per_direction"), threads, needed / 1073741824.0,
          particles, nodes, machine / 1073741824.0));
  }

  RunOutcome run(const ProgressSink& progress, const RestartPlan& restart) override {
    refuse_what_cannot_fit();
    Model model;
    model.grid = setup_.grid;
    seed_particles(model.particles);
    if (model.particles.size() == 0)
      throw ConfigError(fmt::format("the body holds no particle centre at cells = {}: use more cells",
                                    config_.integer("cells")));
    seed_tracers(model.tracers);
    SceneStages stages;
    if (setup_.stages) stages = setup_.stages(model.particles, model.grid);
    if (setup_.second_material) {
      stages.second_material = setup_.second_material;
      stages.second_material_from = first_material_count_;
    }
    if (!setup_.force_free && fault_ != Fault::no_body_force) {
      std::shared_ptr<mms::ForceField> field = setup_.fast_body_force;
      if (!field) field = mms::derived_force_field(setup_.solution);
      stages.body_force = std::make_shared<mms::ManufacturedBodyForce>(field, force_quadrature(), setup_.geometry);
    }
    if (implicit()) {
#ifdef MPMVV_HAVE_SUNDIALS
      const double ramp = std::isfinite(setup_.smooth_until) ? setup_.smooth_until : loop_.end_time;
      loop_.fixed_step = ramp / double(config_.integer("load_steps"));
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
    if (!restart.path.empty()) {
      if (!stepper_->restartable())
        throw ConfigError("a restart file (--checkpoint-every, --pause-at, --resume) holds the state of explicit "
                          "runs only: solver = \"implicit\" keeps its own");
      if (restart.resume) {
        read_state(restart.path, resumed);
        checkpoints.resume = &resumed;
      }
      checkpoints.every_seconds = restart.every_seconds;
      checkpoints.pause_at = restart.pause_at;
      checkpoints.save = [this, &restart](const LoopState& state) { save_state(restart, state); };
    }
    outcome_ = run_time_loop(*stepper_, loop_, *this, progress, 1.0, checkpoints);
    return outcome_;
  }

  // The run's state between two steps, and what the case has recorded so far
  // (persist): written to a partial file and renamed, so that a run killed
  // while it saves keeps the state it saved before.
  void save_state(const RestartPlan& restart, const LoopState& state) {
    const std::string partial = restart.path + ".partial";
    const auto start = std::chrono::steady_clock::now();
    try {
      h5::File file = h5::File::create(partial);
      {
        h5::Group root = file.root();
        for (const auto& [name, value] : restart.identity) root.set_attribute(name, value);
        root.set_attribute("time", state.t);
        root.set_attribute("steps", std::int64_t(state.steps));
        StateArchive a = StateArchive::writing(root.create_group("state"));
        LoopState loop = state;
        a.field("loop", loop);
        a.field("stepper", *stepper_);
        a.field("scene", *this);
      }
      file.save();
      fs::rename(partial, restart.path);
      if (restart.tell)
        restart.tell(fmt::format("state at t = {:.6g} s (step {}) saved to {}: {:.3g} MB in {:.3g} s", state.t,
                                 state.steps, restart.path, double(fs::file_size(restart.path)) / 1e6,
                                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()),
                     false);
    } catch (const std::exception& e) {
      std::error_code ec;
      fs::remove(partial, ec);
      if (restart.tell) restart.tell(fmt::format("saving the state to {} failed: {}", restart.path, e.what()), true);
    }
  }

  void read_state(const std::string& path, LoopState& loop) {
    try {
      const h5::File file = h5::File::open_read(path);
      StateArchive a = StateArchive::reading(file.root().open_group("state"));
      a.field("loop", loop);
      a.field("stepper", *stepper_);
      a.field("scene", *this);
    } catch (const std::exception& e) {
      throw ConfigError(fmt::format("the restart file {} cannot be read ({}): remove it to start again", path,
                                    e.what()));
    }
  }

  // What the observer has recorded (the rest is rebuilt as the case is set
  // up: seeding, tracers, probes).
  void persist(StateArchive& a) {
    a.field("line_records", line_records_);
    a.field("point_time", point_time_);
    a.field("point_simulated", point_simulated_);
    a.field("point_exact", point_exact_);
    a.field("circle_simulated", circle_simulated_);
    a.field("circle_exact", circle_exact_);
    a.field("circle_spectrum", circle_spectrum_);
    a.field("output_times", output_times_);
    a.field("history_time", history_time_);
    a.field("history_values", history_values_);
    a.field("monitor_rows", monitor_rows_);
    a.field("j_ratio", j_ratio_);
    a.field("sampled_motion", sampled_motion_);
    a.field("initial_energy", initial_energy_);
    a.field("largest_energy", largest_energy_);
    a.field("rule_step", rule_step_);
    a.field("stop", stop_);
    a.field("errors", errors_);
    a.field("integrated", integrated_);
    bool settling = settling_.has_value();
    a.field("settling", settling);
    if (a.reads()) {
      settling_.reset();
      if (settling) settling_.emplace(*setup_.settling, loop_.end_time, !implicit());
    }
    if (settling_) a.field("settling_watch", *settling_);
  }

  bool implicit() const { return config_.has("solver") && config_.text("solver") == "implicit"; }

  mms::ForceQuadrature force_quadrature() const {
    return config_.has("body_force_quadrature") && config_.text("body_force_quadrature") == "domain"
               ? mms::ForceQuadrature::domain
               : mms::ForceQuadrature::centroid;
  }

  double cell_size() const override { return setup_.grid.h; }
  Geometry geometry() const override { return setup_.geometry; }
  std::string body_force_kind() const override {
    if (setup_.force_free) return setup_.loading.empty() ? "none" : "none; " + setup_.loading;
    const std::string kind = setup_.fast_body_force ? "closed form" : "derived";
    return force_quadrature() == mms::ForceQuadrature::domain ? kind + ", mean over each particle's domain" : kind;
  }
  Measurements measurements() const override {
    if (!stepper_) return {};
    Measurements m;
    if (setup_.measure) m = setup_.measure(RunRecord{point_time_, point_simulated_, *stepper_});
    for (const auto& s : stepper_->statistics()) m.push_back(s);
    if (settling_) {
      const Settling s = settling_->measure(outcome_.time_reached, *stepper_);
      m.push_back({"settling_displacement", s.displacement});
      m.push_back({"settling_strain", s.strain});
    }
    if (!monitor_rows_.empty()) {
      // The energy balance at the last output (see record_monitors).
      m.push_back({"energy_created", monitor_rows_.back().created});
      m.push_back({"energy_scale", largest_energy_});
    }
    return m;
  }
  std::string seeding() const override { return exact_seeding_ ? "exact" : "centre"; }
  double particle_volume() const override { return particle_volume_; }
  double body_volume() const override {
#ifdef MPMVV_HAVE_CGAL
    if (setup_.body) {
      const AreaMoments m = setup_.body->whole();
      return setup_.geometry == Geometry::axisymmetric ? m.moment_x : m.area;
    }
#endif
    return std::numeric_limits<double>::quiet_NaN();
  }
  std::size_t particle_count() const override { return stepper_ ? stepper_->model().particles.size() : 0; }
  const ErrorTable& errors() const override { return errors_; }

  RunHealth health() const override {
    std::vector<HealthSample> samples;
    for (const MonitorRow& r : monitor_rows_)
      samples.push_back({r.time, r.min_J_ratio, r.max_J_ratio, r.worst_J_reference, r.created, r.energy_scale});
    return judge_health(samples, errors_,
                        {config_.real("health_J_factor"), config_.real("health_energy_loss_factor"),
                         setup_.exact_motion},
                        sampled_motion_);
  }

  std::string error_description() const override {
    return "L1_<line>: eq. 3.1 of 000_1dbcb8acb6dddab9.txt, the mean over the line's material points of "
           "|q_sim - q_exact| for the line's quantity (its 'quantity' attribute; rad or m); particle_L1, "
           "particle_L2, particle_Linf: norms of the displacement error |x_p - x_exact(X_p, t)| over all "
           "particles, weighted by reference volume (m); particle_pressure_L2: the reference-volume-weighted RMS error "
           "of the in-plane mean stress -(sigma_xx + sigma_yy)/2 (Pa); particle_deformation_L2: the reference-volume-"
           "weighted RMS of |F_p - F_exact(X_p, t)| (Frobenius, with F_33; dimensionless); particle_velocity_L2: the reference-volume-"
           "weighted RMS of |v_p - v_exact(X_p, t)| (m/s); exact_displacement_L2: the reference-volume-"
           "weighted RMS of the exact displacement |x_exact - X_p| (m); particle_relative_L2_integrated: "
           "sqrt(int_0^t sum V_p0 |x_p - x_exact|^2 dt / int_0^t sum V_p0 |x_exact - X_p|^2 dt), trapezoid rule over "
           "the start and the output times (the norm the total Lagrangian MPM literature reports for the ring); "
           "error_*: the scene's own relative errors "
           "against its exact "
           "solution (reports/results-format.md)";
  }

  void write_results(h5::Group& root) const override {
    write_particles(root, stepper_->model().particles);
    h5::Group probes = root.create_group("probes");
    const std::size_t outputs = output_times_.size();
    for (std::size_t k = 0; k < setup_.lines.size(); ++k) {
      const ProbeLine& line = setup_.lines[k];
      h5::Group g = probes.create_group(line.name);
      const char* q = to_string(line.quantity);
      g.set_attribute("quantity", q);
      if (line.reference_angle) g.set_attribute("reference_angle", *line.reference_angle);
      g.set_attribute("description", fmt::format("material points along {}; {} at each output time", line.parameter_name, q));
      const std::size_t n = line.reference.size();
      g.write(line.parameter_name, line.parameter, {n});
      g.write("reference_position", flatten_points(line.reference), {n, 2});
      g.write("time", output_times_, {outputs});
      g.write(q, flatten(line_records_[k].simulated), {outputs, n});
      g.write(std::string("exact_") + q, flatten(line_records_[k].exact), {outputs, n});
    }
    for (std::size_t k = 0; k < setup_.points.size(); ++k) {
      const ProbePoint& point = setup_.points[k];
      h5::Group g = probes.create_group(point.name);
      const char* q = to_string(point.quantity);
      g.set_attribute("quantity", q);
      g.set_attribute("reference_position", std::vector<double>{point.reference.x(), point.reference.y()});
      if (setup_.geometry == Geometry::plane_strain) {
        g.set_attribute("reference_radius", point.reference.norm());
        g.set_attribute("reference_angle", std::atan2(point.reference.y(), point.reference.x()));
      }
      g.set_attribute("description", fmt::format("history of {} at the material point after every step", q));
      g.write("time", point_time_, {point_time_.size()});
      g.write(q, point_simulated_[k], {point_time_.size()});
      g.write(std::string("exact_") + q, point_exact_[k], {point_time_.size()});
    }
    if (setup_.circle) {
      h5::Group g = probes.create_group("circle");
      const char* q = to_string(setup_.circle->quantity);
      g.set_attribute("quantity", q);
      g.set_attribute("reference_radius", setup_.circle->radius);
      g.set_attribute("description", fmt::format("material circle: {} around it at each output time", q));
      g.write("reference_angle", circle_angle_, {circle_angle_.size()});
      g.write("time", output_times_, {outputs});
      g.write(q, flatten(circle_simulated_), {outputs, circle_angle_.size()});
      g.write(std::string("exact_") + q, flatten(circle_exact_), {outputs, circle_angle_.size()});
#ifdef MPMVV_HAVE_FFTW
      if (outputs > 0) g.write("error_spectrum", flatten(circle_spectrum_), {outputs, circle_spectrum_.front().size()});
#endif
    }
    if (setup_.history) {
      h5::Group g = probes.create_group("history");
      g.set_attribute("description", "scalars of the scene after every step");
      g.write("time", history_time_, {history_time_.size()});
      for (std::size_t k = 0; k < setup_.history_names.size(); ++k)
        g.write(setup_.history_names[k], history_values_[k], {history_values_[k].size()});
    }
    if (setup_.write_extra) setup_.write_extra(probes);
    write_monitors(probes);
    write_settling(root);
  }

  // A static scene's distance from its static state at the end (settling.hpp).
  void write_settling(h5::Group& root) const {
    if (!settling_ || !stepper_) return;
    const double end = outcome_.time_reached;
    const Settling s = settling_->measure(end, *stepper_);
    h5::Group g = root.create_group("settling");
    g.set_attribute("description",
                    settling_->relaxes()
                        ? "how far the end still is from the static state the damped run relaxes to "
                          "(tools/app/settling.hpp): what the particles (displacement [m], RMS over the body; strain, "
                          "RMS of the symmetric part of F's change) and each error norm read at the end (norms, in "
                          "its unit) moved over the last interval of 1 / decay_rate from kept_time, over "
                          "exp(decay_rate (end - kept_time)) - 1"
                        : "how far the end still is from equilibrium: the Newton correction one more iteration of the "
                          "last load step would make, its mass-weighted RMS over the grid (displacement [m]) and the "
                          "RMS over the body of its strain, from its energy norm (strain)");
    g.set_attribute("method", settling_->relaxes() ? "relaxation" : "newton");
    g.set_attribute("displacement", s.displacement);
    g.set_attribute("strain", s.strain);
    if (!settling_->relaxes()) return;
    g.set_attribute("decay_rate", settling_->decay_rate());
    g.set_attribute("kept_time", settling_->kept_at());
    const bool read_at_end = !errors_.time.empty() && std::abs(errors_.time.back() - end) <= 1e-9 * std::max(1.0, end);
    h5::Group norms = g.create_group("norms");
    for (const auto& [name, value] : settling_->norm_settling(end, [&](const std::string& column) {
           const std::vector<double>* values = errors_.find(column);
           return read_at_end && values && !values->empty() ? values->back()
                                                            : std::numeric_limits<double>::quiet_NaN();
         }))
      norms.set_attribute(name, value);
  }

  void write_monitors(h5::Group& probes) const {
    h5::Group g = probes.create_group("monitors");
    g.set_attribute("description",
                    "the run's health at each output time (solver/monitors.hpp): kinetic and strain energy, the work "
                    "done on the particles by body forces and tractions, node constraints, contact and damping, the "
                    "energy made from nothing (kinetic + strain - initial - work) and the scale the blow-up and "
                    "health tests divide it by (the larger of the initial energy and the largest work yet done by any "
                    "one agent, as of each output time), the angular momentum about the origin and the "
                    "exact motion's over the same particles [kg m^2/s per unit depth; NaN in r-z], J's range and that of J / J_exact (J_exact = 1 without an exact motion), the largest particle "
                    "speed over its wave speed, the largest CPDI domain distortion (1: square), particles at the "
                    "grid's edge, CPDI corner domains turned over, and what lifts the signal speed of the CFL step above the small-strain wave speed: "
                    "the particle's state and density (max c_p / c0, c0 at the reference density) and the basis (max k_p) [J per unit depth; per radian in r-z]");
    g.set_attribute("initial_energy", initial_energy_);
    const std::size_t n = monitor_rows_.size();
    auto column = [&](const char* name, auto get) {
      std::vector<double> v;
      for (const MonitorRow& r : monitor_rows_) v.push_back(get(r));
      g.write(name, v, {n});
    };
    column("time", [](const MonitorRow& r) { return r.time; });
    column("kinetic_energy", [](const MonitorRow& r) { return r.monitors.kinetic; });
    column("strain_energy", [](const MonitorRow& r) { return r.monitors.strain; });
    column("work_body_force", [](const MonitorRow& r) { return r.work.body; });
    column("work_constraints", [](const MonitorRow& r) { return r.work.constraints; });
    column("work_contact", [](const MonitorRow& r) { return r.work.contact; });
    column("work_damping", [](const MonitorRow& r) { return r.work.damping; });
    column("energy_created", [](const MonitorRow& r) { return r.created; });
    column("energy_scale", [](const MonitorRow& r) { return r.energy_scale; });
    column("angular_momentum", [](const MonitorRow& r) { return r.monitors.angular_momentum; });
    column("exact_angular_momentum", [](const MonitorRow& r) { return r.exact_angular_momentum; });
    column("min_J", [](const MonitorRow& r) { return r.monitors.min_J; });
    column("max_J", [](const MonitorRow& r) { return r.monitors.max_J; });
    column("min_J_over_exact", [](const MonitorRow& r) { return r.min_J_ratio; });
    column("max_J_over_exact", [](const MonitorRow& r) { return r.max_J_ratio; });
    column("max_speed_over_wave_speed", [](const MonitorRow& r) { return r.monitors.max_mach; });
    column("max_domain_distortion", [](const MonitorRow& r) { return r.monitors.max_distortion; });
    column("particles_near_edge", [](const MonitorRow& r) { return double(r.monitors.near_edge); });
    column("folded_domains", [](const MonitorRow& r) { return double(r.monitors.folded_domains); });
    column("max_wave_speed_ratio", [](const MonitorRow& r) { return r.monitors.max_wave_speed_ratio; });
    column("max_basis_stiffening", [](const MonitorRow& r) { return r.monitors.max_basis_stiffening; });
    if (config_.integer("stable_step_iterations") > 0) {
      column("largest_frequency", [](const MonitorRow& r) { return r.largest_frequency; });
      column("stable_step", [](const MonitorRow& r) { return 2.0 / r.largest_frequency; });
      column("cfl_step", [](const MonitorRow& r) { return r.cfl_step; });
    }
  }

 private:
  template <class Rows>
  static std::vector<double> flatten(const Rows& rows) {
    std::vector<double> out;
    for (const auto& r : rows) out.insert(out.end(), r.begin(), r.end());
    return out;
  }
  static std::vector<double> flatten_points(const std::vector<Vec2>& points) {
    std::vector<double> out;
    for (const Vec2& p : points) {
      out.push_back(p.x());
      out.push_back(p.y());
    }
    return out;
  }

  // Particles on a regular sub-lattice of every cell, in cell order, so that
  // neighbours in memory are neighbours in space. With exact seeding a
  // sub-cell the boundary cuts holds the part of the body inside it: its exact
  // area and centroid; slivers under a tenth of a sub-cell join the largest
  // piece of their cell, and a clipped particle's domain shrinks to its area.
  // With centre seeding a particle sits wherever its sub-cell centre lies in
  // the body. Each starts in the exact state at t = 0, from the same
  // definition as the force. In r-z a particle's volume is per radian: the
  // integral of r over its area.
  struct Piece {
    Vec2 centroid;
    double area;      // int dA
    double moment_r;  // int x dA (r in r-z)
    std::vector<Vec2> outline;  // exact CPDI only: the clipped piece's outline (empty: the whole sub-cell)
  };

  // Exact CPDI domains follow a clipped piece's outline, arcs in chords of a
  // quarter of the particle spacing (the chord's sagitta, spacing^2 / (128 R),
  // is far below what a piece's area can tell).
  // Corner domains start from each particle's parallelogram (domain_corners.hpp).
  bool outlines() const {
    return options_.method == Method::cpdi_exact && options_.cpdi_domain != CpdiDomain::corners && exact_seeding_;
  }

  // The outline of a piece and a sliver joined to it: a whole sub-cell's
  // square where either has none, then the sliver's ring on a bridge
  // (append_ring).
  static std::vector<Vec2> joined_outline(const Piece& piece, const Piece& sliver, double spacing) {
    auto ring = [&](const Piece& q) {
      if (!q.outline.empty()) return q.outline;
      const Vec2 l = 0.5 * spacing * Vec2(1.0, 1.0), lo = q.centroid - l, hi = q.centroid + l;
      return std::vector<Vec2>{lo, Vec2(hi.x(), lo.y()), hi, Vec2(lo.x(), hi.y())};
    };
    std::vector<Vec2> out = ring(piece);
    append_ring(out, ring(sliver));
    return out;
  }

  std::vector<Piece> pieces_of_cell(int i, int j, int ppd) const {
    const GridGeometry& grid = setup_.grid;
    const double spacing = grid.h / ppd;
    std::vector<Piece> pieces;
    for (int b = 0; b < ppd; ++b)
      for (int a = 0; a < ppd; ++a) {
        const Vec2 lower = grid.node_position(i, j) + spacing * Vec2(a, b);
        const Vec2 centre = lower + 0.5 * spacing * Vec2(1.0, 1.0);
        const Piece whole{centre, spacing * spacing, spacing * spacing * centre.x(), {}};
#ifdef MPMVV_HAVE_CGAL
        if (exact_seeding_) {
          const Body& body = *setup_.body;
          if (body.boundary_may_meet(lower, lower + spacing * Vec2(1.0, 1.0))) {
            const AreaMoments m = body.clip(lower, lower + spacing * Vec2(1.0, 1.0));
            if (m.area > 1e-14 * spacing * spacing) {
              pieces.push_back({m.centroid(), m.area, m.moment_x, {}});
              if (outlines()) pieces.back().outline = body.clip_outline(lower, lower + spacing * Vec2(1.0, 1.0),
                                                                         0.25 * spacing);
            }
          } else if (body.contains(centre)) {
            pieces.push_back(whole);
          }
          continue;
        }
#endif
        if (setup_.contains(centre)) pieces.push_back(whole);
      }
    // Slivers join the largest piece of the cell.
    const double sliver = 0.1 * spacing * spacing;
    auto largest = std::max_element(pieces.begin(), pieces.end(),
                                    [](const Piece& x, const Piece& y) { return x.area < y.area; });
    if (largest != pieces.end()) {
      Piece merged = *largest;
      std::vector<Piece> kept;
      for (auto it = pieces.begin(); it != pieces.end(); ++it) {
        if (it == largest) continue;
        if (it->area < sliver) {
          merged.centroid = (merged.centroid * merged.area + it->centroid * it->area) / (merged.area + it->area);
          merged.area += it->area;
          merged.moment_r += it->moment_r;
          if (outlines()) merged.outline = joined_outline(merged, *it, spacing);
        } else {
          kept.push_back(*it);
        }
      }
      kept.push_back(merged);
      pieces = std::move(kept);
    }
    return pieces;
  }

  void seed_particles(Particles& P) {
    const GridGeometry& grid = setup_.grid;
    const int ppd = int(config_.integer("particles_per_direction"));
    const double spacing = grid.h / ppd;
    std::vector<Piece> pieces;
    for (int j = 0; j < grid.cells_y; ++j)
      for (int i = 0; i < grid.cells_x; ++i)
        for (const Piece& piece : pieces_of_cell(i, j, ppd)) pieces.push_back(piece);
    // A second material's particles after the first's, each in seeding order.
    if (setup_.second_material) {
      const auto second = std::stable_partition(pieces.begin(), pieces.end(), [this](const Piece& piece) {
        return !setup_.in_second_material(piece.centroid);
      });
      first_material_count_ = std::size_t(second - pieces.begin());
    }
    P.resize(pieces.size());
    const bool axisymmetric = setup_.geometry == Geometry::axisymmetric;
    if (axisymmetric) {
      P.hoop_stretch.resize(pieces.size());
      P.hoop_stress.resize(pieces.size());
    }
    const double density = setup_.solution->density();
    particle_volume_ = 0.0;
    for (std::size_t p = 0; p < pieces.size(); ++p) {
      const Vec2 X = pieces[p].centroid;
      const mms::ExactFields f = setup_.solution->state(X, 0.0);
      const double reference_volume = axisymmetric ? pieces[p].moment_r : pieces[p].area;
      P.reference_position[p] = X;
      P.position[p] = f.position;
      P.velocity[p] = f.velocity;
      P.deformation_gradient[p] = f.deformation_gradient;
      P.stress[p] = f.cauchy_stress;
      P.reference_volume[p] = reference_volume;
      P.volume[p] = f.J * reference_volume;
      P.mass[p] = density * reference_volume;
      particle_volume_ += reference_volume;
      if (axisymmetric) {
        P.hoop_stretch[p] = f.hoop_stretch;
        P.hoop_stress[p] = f.cauchy_stress_33;
      }
    }
    if (options_.method != Method::linear) {
      P.half_size.resize(pieces.size());
      for (std::size_t p = 0; p < pieces.size(); ++p)
        P.half_size[p] = 0.5 * std::sqrt(pieces[p].area) * Vec2(1.0, 1.0);
    }
    if (outlines()) {
      P.domain_first.assign(pieces.size() + 1, 0);
      P.domain_vertex.clear();
      for (std::size_t p = 0; p < pieces.size(); ++p) {
        for (const Vec2& v : pieces[p].outline) P.domain_vertex.push_back(v - pieces[p].centroid);
        P.domain_first[p + 1] = std::uint32_t(P.domain_vertex.size());
      }
    }
    (void)spacing;
  }

  void seed_tracers(std::vector<Vec2>& tracers) {
    const mms::ExactSolution& s = *setup_.solution;
    line_first_.clear();
    for (const ProbeLine& line : setup_.lines) {
      line_first_.push_back(tracers.size());
      for (const Vec2& X : line.reference) tracers.push_back(s.position(X, 0.0));
    }
    line_records_.assign(setup_.lines.size(), {});
    point_first_ = tracers.size();
    for (const ProbePoint& point : setup_.points) tracers.push_back(s.position(point.reference, 0.0));
    point_simulated_.assign(setup_.points.size(), {});
    point_exact_.assign(setup_.points.size(), {});
    circle_first_ = tracers.size();
    circle_angle_.clear();
    circle_reference_.clear();
    if (setup_.circle) {
      for (int j = 0; j < setup_.circle->points; ++j) {
        const double Theta = 2.0 * pi * j / setup_.circle->points;
        const Vec2 X = setup_.circle->radius * Vec2(std::cos(Theta), std::sin(Theta));
        circle_angle_.push_back(Theta);
        circle_reference_.push_back(X);
        tracers.push_back(s.position(X, 0.0));
      }
    }
    errors_ = ErrorTable{};
    for (const ProbeLine& line : setup_.lines) errors_.add_column("L1_" + line.name);
    if (setup_.exact_motion)
      for (const char* name : {"particle_L1", "particle_L2", "particle_Linf", "particle_pressure_L2",
                               "particle_deformation_L2", "particle_velocity_L2", "exact_displacement_L2",
                               "particle_relative_L2_integrated"})
        errors_.add_column(name);
    for (const std::string& name : setup_.extra_error_names) errors_.add_column(name);
    history_time_.clear();
    history_values_.assign(setup_.history_names.size(), {});
  }

  std::optional<double> exact_signal_fraction(const std::string& norm, double time) const override {
    if (!setup_.solution) return std::nullopt;
    if (std::isnan(time)) time = loop_.end_time;
    std::function<double(double)> signal;
    if (norm.starts_with("L1_")) {
      const auto line = std::find_if(setup_.lines.begin(), setup_.lines.end(),
                                     [&](const ProbeLine& l) { return "L1_" + l.name == norm; });
      if (line == setup_.lines.end() || line->reference.empty()) return std::nullopt;
      signal = [this, &line = *line](double t) {
        double sum = 0.0;
        for (const Vec2& X : line.reference) sum += std::abs(exact_at(line.quantity, X, t));
        return sum / double(line.reference.size());
      };
    } else if (norm == "particle_L1" || norm == "particle_L2" || norm == "particle_Linf") {
      // The body sampled on a 48 x 48 lattice over the walls' box.
      std::vector<Vec2> body;
      const Vec2 lo = setup_.grid.wall_lower(), hi = setup_.grid.wall_upper();
      for (int j = 0; j < 48; ++j)
        for (int i = 0; i < 48; ++i) {
          const Vec2 X = lo + (hi - lo).cwiseProduct(Vec2((i + 0.5) / 48.0, (j + 0.5) / 48.0));
          if (setup_.contains(X)) body.push_back(X);
        }
      if (body.empty()) return std::nullopt;
      signal = [this, body = std::move(body)](double t) {
        double sum = 0.0;
        for (const Vec2& X : body) sum += (setup_.solution->position(X, t) - X).squaredNorm();
        return std::sqrt(sum / double(body.size()));
      };
    } else {
      return std::nullopt;
    }
    std::vector<double> times = loop_.output_times;
    if (times.empty() || times.back() < loop_.end_time) times.push_back(loop_.end_time);
    double largest = 0.0, at = std::numeric_limits<double>::quiet_NaN();
    for (double t : times) {
      const double s = signal(t);
      largest = std::max(largest, s);
      if (std::abs(t - time) <= 1e-9 * std::max(1.0, std::abs(time))) at = s;
    }
    if (!std::isfinite(at) || !(largest > 0.0)) return std::nullopt;
    return at / largest;
  }

  double value_at(ProbeQuantity q, const Vec2& x, const Vec2& X, double t) const {
    return probe_value(q, setup_.geometry, x, X, setup_.solution->position(X, t));
  }
  double exact_at(ProbeQuantity q, const Vec2& X, double t) const {
    const Vec2 x = setup_.solution->position(X, t);
    return probe_value(q, setup_.geometry, x, X, x);
  }

  // Sums over the particles, weighted by reference volume V_p0, of the
  // displacement error e_p = |x_p - x_exact(X_p, t)| (e, e^2, its largest)
  // and of the exact displacement |x_exact - X_p|^2.
  struct DisplacementSums {
    double weight = 0.0, l1 = 0.0, l2 = 0.0, linf = 0.0, exact2 = 0.0;
  };
  DisplacementSums displacement_sums(const Particles& P, double t) const {
    DisplacementSums d;
    for (std::size_t p = 0; p < P.size(); ++p) {
      const Vec2 x_exact = setup_.solution->position(P.reference_position[p], t);
      const double e = (P.position[p] - x_exact).norm();
      const double w = P.reference_volume[p];
      d.weight += w;
      d.l1 += w * e;
      d.l2 += w * e * e;
      d.linf = std::max(d.linf, e);
      d.exact2 += w * (x_exact - P.reference_position[p]).squaredNorm();
    }
    return d;
  }

  // The energy at the start, for the balance (monitors.hpp), and the first
  // point of the time-integrated error.
  void initial(const Stepper& s) override {
    integrated_ = {};
    if (setup_.exact_motion) {
      const DisplacementSums d = displacement_sums(s.model().particles, 0.0);
      integrated_.add(0.0, d.l2, d.exact2);
    }
    const Monitors m = s.monitors();
    initial_energy_ = m.kinetic + m.strain;
    largest_energy_ = initial_energy_;
    monitor_rows_.clear();
    sampled_motion_ = 0.0;
    stop_ = {};
    settling_.reset();
    if (setup_.settling) {
      settling_.emplace(*setup_.settling, loop_.end_time, !implicit());
      if (settling_->observe(0.0, s.model().particles)) settling_->keep_norms(settling_norms(0.0, s));
    }
  }

  std::pair<std::string, std::string> stop() const override { return stop_; }

  // Monitors at an output time, and the energy balance: what the run made
  // from nothing, E - E_0 - W (W the work done on it), against the larger of
  // the energy it started with and the largest work done on it so far.
  void record_monitors(double t, const Stepper& s) {
    const Monitors m = s.monitors();
    const EnergyLedger& w = s.ledger();
    const double energy = m.kinetic + m.strain;
    const double created = energy - initial_energy_ - w.total();
    // The scale: the energy at the start and the largest work yet done on the
    // run by any one agent (not the energy now, which a blow-up inflates).
    largest_energy_ = std::max({largest_energy_, std::abs(w.body), std::abs(w.constraints), std::abs(w.contact),
                                std::abs(w.damping)});
    double frequency = std::numeric_limits<double>::quiet_NaN(), cfl_step = frequency;
    if (const int iterations = int(config_.integer("stable_step_iterations")); iterations > 0) {
      frequency = s.largest_frequency(iterations);
      cfl_step = rule_step_;
    }
    // The exact motion's angular momentum: with the errors at this output
    // time, which evaluate the exact state of every particle (at_output).
    const double exact_spin = std::numeric_limits<double>::quiet_NaN();
    monitor_rows_.push_back({t, m, w, created, frequency, cfl_step, exact_spin, largest_energy_, m.min_J, m.max_J,
                             Vec2::Constant(std::numeric_limits<double>::quiet_NaN())});
    const double factor = config_.real("energy_blowup_factor");
    if (created > factor * largest_energy_ && created > 0.0)
      stop_ = {"energy blow-up",
               fmt::format("at t = {:.6g} s the run made {:.4g} J of energy from nothing, {:.3g} times the {:.4g} J it "
                           "started with or was given (energy_blowup_factor = {})",
                           t, created, created / largest_energy_, largest_energy_, factor)};
  }

  // The range of J_p / J_exact at this output time into its monitor row; a
  // ratio that is not a number (a NaN J) counts as farthest of all.
  void record_J_ratio(const Particles& P) {
    MonitorRow& row = monitor_rows_.back();
    row.min_J_ratio = std::numeric_limits<double>::infinity();
    row.max_J_ratio = 0.0;
    double farthest = -1.0;
    bool not_a_number = false;
    for (std::size_t p = 0; p < j_ratio_.size(); ++p) {
      const double r = j_ratio_[p];
      const double distance = r > 0.0 ? std::abs(std::log(r)) : std::numeric_limits<double>::infinity();
      if (!(distance <= farthest)) {  // NaN is farther than anything
        farthest = distance;
        row.worst_J_reference = P.reference_position[p];
      }
      not_a_number = not_a_number || std::isnan(r);
      row.min_J_ratio = std::min(row.min_J_ratio, r);
      row.max_J_ratio = std::max(row.max_J_ratio, r);
    }
    if (not_a_number) row.min_J_ratio = row.max_J_ratio = std::numeric_limits<double>::quiet_NaN();
  }

  void step_rule(double dt) override { rule_step_ = dt; }

  // The RMS exact displacement over every k-th particle (about 256 of them,
  // weighted by reference volume), after every step: the health verdict's
  // measure of the whole motion between the output times (health.hpp).
  void sample_motion(double t, const Particles& P) {
    const std::size_t n = P.size(), stride = std::max<std::size_t>(1, n / 256);
    double weight = 0.0, exact2 = 0.0;
    for (std::size_t p = 0; p < n; p += stride) {
      const Vec2 X = P.reference_position[p];
      weight += P.reference_volume[p];
      exact2 += P.reference_volume[p] * (setup_.solution->position(X, t) - X).squaredNorm();
    }
    if (weight > 0.0) sampled_motion_ = std::max(sampled_motion_, std::sqrt(exact2 / weight));
  }

  void after_step(double t, const Stepper& s) override {
    if (setup_.exact_motion) sample_motion(t, s.model().particles);
    if (settling_ && settling_->observe(t, s.model().particles)) settling_->keep_norms(settling_norms(t, s));
    if (setup_.history) {
      const std::vector<double> values = setup_.history(t, s);
      history_time_.push_back(t);
      for (std::size_t k = 0; k < values.size(); ++k) history_values_[k].push_back(values[k]);
    }
    point_time_.push_back(t);
    for (std::size_t k = 0; k < setup_.points.size(); ++k) {
      const ProbePoint& point = setup_.points[k];
      point_simulated_[k].push_back(value_at(point.quantity, s.model().tracers[point_first_ + k], point.reference, t));
      point_exact_[k].push_back(exact_at(point.quantity, point.reference, t));
    }
  }

  // Eq. 3.1 on line k at time t: the mean over its material points of
  // |q_sim - q_exact|; their values into `simulated` and `exact` when given.
  double line_l1(std::size_t k, const std::vector<Vec2>& tracers, double t, std::vector<double>* simulated = nullptr,
                 std::vector<double>* exact = nullptr) const {
    const ProbeLine& line = setup_.lines[k];
    double l1 = 0.0;
    for (std::size_t i = 0; i < line.reference.size(); ++i) {
      const double value = value_at(line.quantity, tracers[line_first_[k] + i], line.reference[i], t);
      const double expected = exact_at(line.quantity, line.reference[i], t);
      if (simulated) simulated->push_back(value);
      if (exact) exact->push_back(expected);
      l1 += std::abs(value - expected);
    }
    return l1 / double(line.reference.size());
  }

  // The error norms a static scene reads at its end, at time t, for the
  // settling of each (settling.hpp): the lines' L1, the particle displacement
  // norms and the scene's own columns.
  std::vector<std::pair<std::string, double>> settling_norms(double t, const Stepper& s) const {
    std::vector<std::pair<std::string, double>> norms;
    for (std::size_t k = 0; k < setup_.lines.size(); ++k)
      norms.push_back({errors_.columns[k].first, line_l1(k, s.model().tracers, t)});
    if (setup_.exact_motion) {
      const DisplacementSums d = displacement_sums(s.model().particles, t);
      norms.push_back({"particle_L1", d.l1 / d.weight});
      norms.push_back({"particle_L2", std::sqrt(d.l2 / d.weight)});
      norms.push_back({"particle_Linf", d.linf});
    }
    if (setup_.extra_errors) {
      const std::vector<double> values = setup_.extra_errors(t, RunRecord{point_time_, point_simulated_, s});
      for (std::size_t k = 0; k < values.size() && k < setup_.extra_error_names.size(); ++k)
        norms.push_back({setup_.extra_error_names[k], values[k]});
    }
    return norms;
  }

  void at_output(std::size_t, double t, const Stepper& s) override {
    record_monitors(t, s);
    const std::vector<Vec2>& tracers = s.model().tracers;
    output_times_.push_back(t);
    errors_.time.push_back(t);
    for (std::size_t k = 0; k < setup_.lines.size(); ++k) {
      std::vector<double> sim, ex;
      errors_.columns[k].second.push_back(line_l1(k, tracers, t, &sim, &ex));
      line_records_[k].simulated.push_back(std::move(sim));
      line_records_[k].exact.push_back(std::move(ex));
    }
    if (setup_.circle) {
      std::vector<double> sim, ex, err;
      for (std::size_t j = 0; j < circle_reference_.size(); ++j) {
        const double value = value_at(setup_.circle->quantity, tracers[circle_first_ + j], circle_reference_[j], t);
        const double exact = exact_at(setup_.circle->quantity, circle_reference_[j], t);
        sim.push_back(value);
        ex.push_back(exact);
        err.push_back(value - exact);
      }
      circle_simulated_.push_back(std::move(sim));
      circle_exact_.push_back(std::move(ex));
#ifdef MPMVV_HAVE_FFTW
      circle_spectrum_.push_back(analytic::amplitude_spectrum(err));
#endif
    }
    // Volume-weighted displacement error over all particles.
    std::size_t column = setup_.lines.size();
    if (setup_.exact_motion) {
      const Particles& P = s.model().particles;
      const DisplacementSums d = displacement_sums(P, t);
      const double weight = d.weight;
      errors_.columns[column++].second.push_back(d.l1 / weight);
      errors_.columns[column++].second.push_back(std::sqrt(d.l2 / weight));
      errors_.columns[column++].second.push_back(d.linf);
      // The in-plane mean stress -(sigma_xx + sigma_yy) / 2 against the exact
      // one: its volume-weighted RMS error shows the pressure oscillation of
      // a nearly incompressible solid (volumetric locking). The deformation
      // gradient's error |F_p - F(X_p, t)| (Frobenius, the out-of-plane
      // stretch included) is the strain the stress is computed from: a method
      // can place its particles to second order while each particle's F
      // carries an error of first order from particle to particle, which the
      // displacement norms average away. The velocity's error |v_p -
      // v(X_p, t)| holds what the positions integrate: a drift, and the
      // elastic waves a method excites and the exact motion does not have
      // (their positions' share is their amplitude over their frequency).
      const std::size_t n = P.size();
      const bool axisymmetric = setup_.geometry == Geometry::axisymmetric;  // F_33 = F_theta (out_of_plane_stretch)
      j_ratio_.resize(n);
      // With them the exact motion's angular momentum over the same
      // particles, the reference its monitor is read against (the ring's
      // spin, suites/stiff-vortex.toml).
      ThreadOrderedSums<4> sums;  // pressure, deformation, velocity, spin: the same bits for a given thread count
#pragma omp parallel
      {
        double pressure = 0.0, deformation = 0.0, velocity = 0.0, spin = 0.0;
#pragma omp for schedule(static)
        for (std::size_t p = 0; p < n; ++p) {
          const mms::ExactFields f = setup_.solution->state(P.reference_position[p], t);
          spin += P.mass[p] * (f.position.x() * f.velocity.y() - f.position.y() * f.velocity.x());
          j_ratio_[p] = determinant(P.deformation_gradient[p]) * (axisymmetric ? P.hoop_stretch[p] : 1.0) /
                        (determinant(f.deformation_gradient) * f.hoop_stretch);
          const double e = 0.5 * ((P.stress[p] - f.cauchy_stress).trace());
          pressure += P.reference_volume[p] * e * e;
          const double e33 = (axisymmetric ? P.hoop_stretch[p] : 1.0) - f.hoop_stretch;
          const double e_in_plane = (P.deformation_gradient[p] - f.deformation_gradient).squaredNorm();
          deformation += P.reference_volume[p] * (e_in_plane + e33 * e33);
          velocity += P.reference_volume[p] * (P.velocity[p] - f.velocity).squaredNorm();
        }
        sums.keep({pressure, deformation, velocity, spin});
      }
      const auto [pressure, deformation, velocity, spin] = sums.total();
      record_J_ratio(P);
      if (setup_.geometry == Geometry::plane_strain) monitor_rows_.back().exact_angular_momentum = spin;
      errors_.columns[column++].second.push_back(std::sqrt(pressure / weight));
      errors_.columns[column++].second.push_back(std::sqrt(deformation / weight));
      errors_.columns[column++].second.push_back(std::sqrt(velocity / weight));
      errors_.columns[column++].second.push_back(std::sqrt(d.exact2 / weight));
      integrated_.add(t, d.l2, d.exact2);
      errors_.columns[column++].second.push_back(integrated_.relative());
    }
    if (!setup_.extra_error_names.empty()) {
      const std::vector<double> extra = setup_.extra_errors(t, RunRecord{point_time_, point_simulated_, s});
      if (extra.size() != setup_.extra_error_names.size())
        throw std::logic_error("a problem's extra errors do not match their names");
      for (std::size_t k = 0; k < extra.size(); ++k) errors_.columns[column + k].second.push_back(extra[k]);
    }
  }

  Config config_;
  Fault fault_;
  bool exact_seeding_ = false;
  double particle_volume_ = 0.0;
  std::size_t first_material_count_ = 0;  // with a second material: the particles of the first
  ProblemSetup setup_;
  SolverOptions options_;
  TimeLoopOptions loop_;
  std::unique_ptr<Stepper> stepper_;
  RunOutcome outcome_;

  std::vector<std::size_t> line_first_;
  std::vector<LineRecord> line_records_;
  std::size_t point_first_ = 0;
  std::vector<double> point_time_;
  std::vector<std::vector<double>> point_simulated_, point_exact_;
  std::size_t circle_first_ = 0;
  std::vector<double> circle_angle_;
  std::vector<Vec2> circle_reference_;
  std::vector<std::vector<double>> circle_simulated_, circle_exact_, circle_spectrum_;
  std::vector<double> output_times_;
  std::vector<double> history_time_;
  std::vector<std::vector<double>> history_values_;
  struct MonitorRow {
    double time;
    Monitors monitors;
    EnergyLedger work;
    double created;
    double largest_frequency, cfl_step;  // with stable_step_iterations > 0
    double exact_angular_momentum;       // NaN without an exact motion (or in r-z)
    double energy_scale;                 // the balance's scale at this time (record_monitors)
    // The range of J_p / J_exact(X_p, t) over the particles (J_exact = 1
    // without an exact motion), and the reference position of the particle
    // farthest from 1 in ratio (RunHealth).
    double min_J_ratio, max_J_ratio;
    Vec2 worst_J_reference;
  };
  std::vector<MonitorRow> monitor_rows_;
  std::vector<double> j_ratio_;  // J_p / J_exact at the last output time (exact motion only)
  double sampled_motion_ = 0.0;  // the largest RMS exact displacement sampled after a step (sample_motion)
  double initial_energy_ = 0.0, largest_energy_ = 0.0;
  double rule_step_ = std::numeric_limits<double>::quiet_NaN();  // the time-step rule's last step
  std::pair<std::string, std::string> stop_;
  ErrorTable errors_;
  // The time-integrated relative L2 displacement error, the norm other codes
  // publish for the ring (the vortex of the total Lagrangian MPM literature):
  //   sqrt( int_0^t sum_p V_p0 |x_p - x_exact|^2 dt / int_0^t sum_p V_p0 |x_exact - X_p|^2 dt ),
  // both integrals by the trapezoid rule over the start and the output times.
  struct TimeIntegral {
    double time = 0.0, error2 = 0.0, exact2 = 0.0;  // the last point
    double error_integral = 0.0, exact_integral = 0.0;
    bool started = false;
    void add(double t, double e2, double u2) {
      if (started) {
        error_integral += 0.5 * (t - time) * (e2 + error2);
        exact_integral += 0.5 * (t - time) * (u2 + exact2);
      }
      time = t;
      error2 = e2;
      exact2 = u2;
      started = true;
    }
    double relative() const {
      return exact_integral > 0.0 ? std::sqrt(error_integral / exact_integral)
                                  : std::numeric_limits<double>::quiet_NaN();
    }
  };
  TimeIntegral integrated_;
  std::optional<SettlingWatch> settling_;  // a static scene's distance from its static state at the end
};

}  // namespace

MmsProblem ring_problem();
MmsProblem axis_aligned_problem();
MmsProblem expanding_ring_problem();
MmsProblem rz_cylinder_problem();
MmsProblem vibrating_bar_problem();
MmsProblem uniaxial_tension_problem();
MmsProblem uniaxial_compression_problem();
MmsProblem shear_problem();
MmsProblem hertz_cylinder_problem();
#ifdef MPMVV_HAVE_SUNDIALS
MmsProblem neo_hookean_bar_problem();
MmsProblem layered_bar_problem();
#endif

const std::vector<MmsProblem>& mms_problems() {
  static const std::vector<MmsProblem> problems = [] {
    std::vector<MmsProblem> p = {ring_problem(),          axis_aligned_problem(),        expanding_ring_problem(),
                                 rz_cylinder_problem(),   vibrating_bar_problem(),       uniaxial_tension_problem(),
                                 uniaxial_compression_problem(), shear_problem(), hertz_cylinder_problem()};
#ifdef MPMVV_HAVE_SUNDIALS
    p.push_back(neo_hookean_bar_problem());  // its exact state is a root found by KINSOL
    p.push_back(layered_bar_problem());      // its frequency too
#endif
    return p;
  }();
  return problems;
}

const MmsProblem* find_mms_problem(const std::string& name) {
  for (const MmsProblem& p : mms_problems())
    if (p.name == name) return &p;
  return nullptr;
}

std::unique_ptr<SceneCase> build_mms_case(const Config& config, const MmsProblem& problem) {
  return std::make_unique<MmsCase>(config, problem);
}

}  // namespace mpmvv::app
