// The ring scene: the ring MMS of PROBLEMS.md section 1 on the Sandia study's
// 3 m square domain with roller walls. It needs a body force and tracers; it
// has no contact and no prescribed velocities.
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <ostream>

#include <fmt/format.h>
#include <fmt/ostream.h>

#include "mms/ring.hpp"
#include "scene.hpp"
#ifdef MPMVV_HAVE_FFTW
#include "spectrum.hpp"
#endif

namespace mpmvv::app {

std::vector<KeySpec> ring_keys() {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<KeySpec> keys = solver_keys(64, 1.0, {0.1, 0.2, 0.25, 0.3, 0.4, 0.5, 0.6, 0.7, 0.75, 0.8, 0.9, 1.0});
  const std::vector<KeySpec> ring = {
      {"amplitude", KeyKind::real, 0.5, "A, the largest angular displacement [rad]", 0.0, 4.0, true},
      {"time_function", KeyKind::text, std::string("cosine"),
       "g(t): cosine = (A/2)(1 - cos 2 pi t) (Sandia report), sine = A sin(pi t) (MMS paper)", -inf, inf, false,
       false, {"cosine", "sine"}},
      {"lambda", KeyKind::real, 577.0, "first Lame constant of the neo-Hookean solid [Pa]"},
      {"mu", KeyKind::real, 385.0, "shear modulus [Pa]", 0.0, inf, true},
      {"density", KeyKind::real, 1000.0, "reference density rho_0 [kg/m^3]", 0.0, inf, true},
      {"inner_radius", KeyKind::real, 0.75, "inner radius R_i of the ring [m]", 0.0, inf, true},
      {"outer_radius", KeyKind::real, 1.25, "outer radius R_o of the ring [m]", 0.0, inf, true},
      {"domain", KeyKind::real, 3.0, "width of the square domain centred on the ring [m]", 0.0, inf, true},
      {"probe_points", KeyKind::integer, std::int64_t(51), "material points on each probe line", 2, 100000},
      {"circle_points", KeyKind::integer, std::int64_t(128),
       "material points on the circle R = (R_i + R_o)/2 for the angular spectrum", 8, 65536},
  };
  keys.insert(keys.end(), ring.begin(), ring.end());
  return keys;
}

namespace {

using std::numbers::pi;

// The ring's force at each particle. The radial factors and the direction of
// each particle's reference position never change, so they are kept per
// particle (particles keep their order for the whole run); a step then costs one
// time-function evaluation and one sin/cos pair per particle.
class RingBodyForce final : public BodyForce {
 public:
  RingBodyForce(const mms::RingMms& mms, const std::vector<Vec2>& reference_position) : mms_(mms) {
    radial_.reserve(reference_position.size());
    direction_.reserve(reference_position.size());
    for (const Vec2& X : reference_position) {
      radial_.push_back(mms_.radial(X.norm()));
      direction_.push_back(X / X.norm());
    }
  }

  void evaluate(double t, const Particles& P, std::vector<Vec2>& b) const override {
    const std::size_t n = P.size();
    if (n != radial_.size()) throw std::logic_error("ring body force: the particle set changed");
    const mms::RingMms::Temporal q = mms_.temporal(t);
#pragma omp parallel for schedule(static)
    for (std::size_t p = 0; p < n; ++p) b[p] = mms_.body_force(radial_[p], direction_[p].x(), direction_[p].y(), q);
  }

 private:
  mms::RingMms mms_;
  std::vector<mms::RingMms::Radial> radial_;
  std::vector<Vec2> direction_;  // X_p / |X_p|: (cos Theta_p, sin Theta_p)
};

// Angular position of a tracer relative to its reference angle, unwrapped
// about the exact value (the error stays far below pi).
double angular_displacement(const Vec2& x, double reference_angle, double exact) {
  const double raw = std::atan2(x.y(), x.x()) - reference_angle - exact;
  return exact + std::remainder(raw, 2.0 * pi);
}

struct ProbeLine {
  std::string name;
  double reference_angle;          // Theta of the line [rad]
  std::size_t first_tracer;
  std::vector<double> radius;      // reference radius of each point
  std::vector<std::vector<double>> simulated, exact;  // per output time
};

class RingCase final : public SceneCase, private RunObserver {
 public:
  explicit RingCase(const Config& c)
      : config_(c), mms_(parameters(c)), options_(solver_options(c)), loop_(time_loop_options(c)) {
    const double domain = c.real("domain");
    grid_.cells_x = grid_.cells_y = int(c.integer("cells"));
    grid_.h = domain / grid_.cells_x;
    grid_.origin = Vec2(-0.5 * domain, -0.5 * domain);
    const auto& p = mms_.parameters();
    if (!(p.outer_radius > p.inner_radius))
      c.reject("outer_radius", fmt::format("must exceed inner_radius = {} (from {})", p.inner_radius,
                                           c.origin("inner_radius").source));
    if (p.outer_radius + 2.0 * grid_.h > 0.5 * domain)
      c.reject("domain", fmt::format("the ring (outer radius {}) needs two cells of clearance inside the "
                                     "{} m domain (h = {:.4g} m)", p.outer_radius, domain, grid_.h));
    if (!(p.lambda > -2.0 / 3.0 * p.mu))
      c.reject("lambda", fmt::format("must exceed -2 mu / 3 = {:.6g} (a positive bulk modulus; mu from {})",
                                     -2.0 / 3.0 * p.mu, c.origin("mu").source));
    if (p.outer_radius - p.inner_radius < grid_.h)
      c.reject("cells", fmt::format("the ring is {} m wide but a cell is {:.4g} m: use more cells",
                                    p.outer_radius - p.inner_radius, grid_.h));
  }

  RunOutcome run(const ProgressSink& progress) override {
    Model model;
    model.grid = grid_;
    seed_particles(model.particles);
    seed_tracers(model.tracers);
    auto body_force = std::make_shared<RingBodyForce>(mms_, model.particles.reference_position);
    stepper_ = make_stepper(std::move(model), options_, mms_.material(), std::move(body_force));
    outcome_ = run_time_loop(*stepper_, loop_, *this, progress);
    return outcome_;
  }

  double cell_size() const override { return grid_.h; }
  std::size_t particle_count() const override { return stepper_ ? stepper_->model().particles.size() : 0; }

  void write_results(h5::Group& root) const override {
    const Particles& P = stepper_->model().particles;
    write_particles(root, P);
    h5::Group probes = root.create_group("probes");
    const std::size_t outputs = output_times_.size();
    for (const ProbeLine& line : lines_) {
      h5::Group g = probes.create_group(line.name);
      g.set_attribute("reference_angle", line.reference_angle);
      g.set_attribute("description", "material points on the line Theta = reference_angle; angular displacement "
                                     "alpha at each output time (rad)");
      g.write("reference_radius", line.radius, {line.radius.size()});
      g.write("time", output_times_, {outputs});
      g.write("angular_displacement", flatten(line.simulated), {outputs, line.radius.size()});
      g.write("exact_angular_displacement", flatten(line.exact), {outputs, line.radius.size()});
    }
    {
      h5::Group g = probes.create_group("point_R1");
      g.set_attribute("reference_radius", point_radius_);
      g.set_attribute("reference_angle", 0.0);
      g.set_attribute("description", "history of the material point (R, Theta) = (R_m, 0) after every step");
      g.write("time", point_time_, {point_time_.size()});
      g.write("angular_displacement", point_simulated_, {point_time_.size()});
      g.write("exact_angular_displacement", point_exact_, {point_time_.size()});
    }
    {
      h5::Group g = probes.create_group("circle");
      g.set_attribute("reference_radius", point_radius_);
      g.set_attribute("description", "material circle R = R_m: angular displacement around it at each output time");
      g.write("reference_angle", circle_angle_, {circle_angle_.size()});
      g.write("time", output_times_, {outputs});
      g.write("angular_displacement", flatten(circle_simulated_), {outputs, circle_angle_.size()});
      g.write("exact_angular_displacement", flatten(circle_exact_), {outputs, circle_angle_.size()});
#ifdef MPMVV_HAVE_FFTW
      if (outputs > 0) {
        const std::size_t modes = circle_spectrum_.front().size();
        g.write("error_spectrum", flatten(circle_spectrum_), {outputs, modes});
      }
#endif
    }
  }

  const ErrorTable& errors() const override { return errors_; }

  std::string error_description() const override {
    return "L1_<line>: eq. 3.1 of 000_1dbcb8acb6dddab9.txt, the mean of |alpha_sim - alpha_exact| over the "
           "line's material points (rad); particle_L1, particle_L2, particle_Linf: norms of the displacement "
           "error |x_p - x_exact(X_p, t)| over all particles, weighted by reference volume (m)";
  }


 private:
  static mms::RingParameters parameters(const Config& c) {
    mms::RingParameters p;
    p.inner_radius = c.real("inner_radius");
    p.outer_radius = c.real("outer_radius");
    p.amplitude = c.real("amplitude");
    p.time_function = c.text("time_function") == "sine" ? mms::RingTimeFunction::sine : mms::RingTimeFunction::cosine;
    p.lambda = c.real("lambda");
    p.mu = c.real("mu");
    p.density = c.real("density");
    return p;
  }

  template <class Rows>
  static std::vector<double> flatten(const Rows& rows) {
    std::vector<double> out;
    for (const auto& r : rows) out.insert(out.end(), r.begin(), r.end());
    return out;
  }

  // Particles on a regular sub-lattice of every cell, kept where their centre
  // lies in the ring; in cell order, so neighbours in memory are neighbours in
  // space. Each starts in the exact state at t = 0.
  void seed_particles(Particles& P) const {
    const int ppd = int(config_.integer("particles_per_direction"));
    const double spacing = grid_.h / ppd;
    std::vector<Vec2> X;
    for (int j = 0; j < grid_.cells_y; ++j)
      for (int i = 0; i < grid_.cells_x; ++i)
        for (int b = 0; b < ppd; ++b)
          for (int a = 0; a < ppd; ++a) {
            const Vec2 x = grid_.node_position(i, j) + spacing * Vec2(a + 0.5, b + 0.5);
            if (mms_.contains(x)) X.push_back(x);
          }
    P.resize(X.size());
    const double volume = spacing * spacing;
    const NeoHookean& material = mms_.material();
    for (std::size_t p = 0; p < X.size(); ++p) {
      const mms::RingState s = mms_.state(X[p], 0.0);
      P.reference_position[p] = X[p];
      P.position[p] = s.position;
      P.velocity[p] = s.velocity;
      P.deformation_gradient[p] = s.deformation_gradient;
      P.stress[p] = material.cauchy_stress(s.deformation_gradient);
      P.reference_volume[p] = volume;
      P.volume[p] = determinant(s.deformation_gradient) * volume;
      P.mass[p] = mms_.parameters().density * volume;
    }
    if (options_.method != Method::linear) P.half_size.assign(X.size(), Vec2(0.5 * spacing, 0.5 * spacing));
  }

  // Probe lines Theta = 0, +45, -45 degrees, the point (R_m, 0) and the circle R_m.
  void seed_tracers(std::vector<Vec2>& tracers) {
    const auto& p = mms_.parameters();
    const int n = int(config_.integer("probe_points"));
    const double angles[3] = {0.0, pi / 4.0, -pi / 4.0};
    const char* names[3] = {"theta0", "theta_plus45", "theta_minus45"};
    lines_.clear();
    for (int k = 0; k < 3; ++k) {
      ProbeLine line{names[k], angles[k], tracers.size(), {}, {}, {}};
      for (int i = 0; i < n; ++i) {
        const double R = p.inner_radius + (p.outer_radius - p.inner_radius) * i / (n - 1);
        line.radius.push_back(R);
        tracers.push_back(mms_.position(R * Vec2(std::cos(angles[k]), std::sin(angles[k])), 0.0));
      }
      lines_.push_back(std::move(line));
    }
    point_radius_ = 0.5 * (p.inner_radius + p.outer_radius);
    point_tracer_ = tracers.size();
    tracers.push_back(mms_.position(Vec2(point_radius_, 0.0), 0.0));
    const int m = int(config_.integer("circle_points"));
    circle_first_ = tracers.size();
    circle_angle_.clear();
    for (int j = 0; j < m; ++j) {
      const double Theta = 2.0 * pi * j / m;
      circle_angle_.push_back(Theta);
      tracers.push_back(mms_.position(point_radius_ * Vec2(std::cos(Theta), std::sin(Theta)), 0.0));
    }
    errors_ = ErrorTable{};
    for (const ProbeLine& line : lines_) errors_.add_column("L1_" + line.name);
    for (const char* name : {"particle_L1", "particle_L2", "particle_Linf"}) errors_.add_column(name);
  }

  void after_step(double t, const Stepper& s) override {
    const double exact = mms_.angle(point_radius_, t);
    point_time_.push_back(t);
    point_exact_.push_back(exact);
    point_simulated_.push_back(angular_displacement(s.model().tracers[point_tracer_], 0.0, exact));
  }

  void at_output(std::size_t, double t, const Stepper& s) override {
    const std::vector<Vec2>& tracers = s.model().tracers;
    output_times_.push_back(t);
    errors_.time.push_back(t);
    for (std::size_t k = 0; k < lines_.size(); ++k) {
      ProbeLine& line = lines_[k];
      std::vector<double> sim, ex;
      double l1 = 0.0;
      for (std::size_t i = 0; i < line.radius.size(); ++i) {
        const double exact = mms_.angle(line.radius[i], t);
        const double alpha = angular_displacement(tracers[line.first_tracer + i], line.reference_angle, exact);
        sim.push_back(alpha);
        ex.push_back(exact);
        l1 += std::abs(alpha - exact);
      }
      errors_.columns[k].second.push_back(l1 / double(line.radius.size()));  // eq. 3.1
      line.simulated.push_back(std::move(sim));
      line.exact.push_back(std::move(ex));
    }
    std::vector<double> sim, ex, err;
    const double exact_circle = mms_.angle(point_radius_, t);
    for (std::size_t j = 0; j < circle_angle_.size(); ++j) {
      const double alpha = angular_displacement(tracers[circle_first_ + j], circle_angle_[j], exact_circle);
      sim.push_back(alpha);
      ex.push_back(exact_circle);
      err.push_back(alpha - exact_circle);
    }
    circle_simulated_.push_back(std::move(sim));
    circle_exact_.push_back(std::move(ex));
#ifdef MPMVV_HAVE_FFTW
    circle_spectrum_.push_back(amplitude_spectrum(err));
#endif
    // Volume-weighted displacement error over all particles.
    const Particles& P = s.model().particles;
    double weight = 0.0, l1 = 0.0, l2 = 0.0, linf = 0.0;
    for (std::size_t p = 0; p < P.size(); ++p) {
      const double e = (P.position[p] - mms_.position(P.reference_position[p], t)).norm();
      const double w = P.reference_volume[p];
      weight += w;
      l1 += w * e;
      l2 += w * e * e;
      linf = std::max(linf, e);
    }
    const std::size_t first = lines_.size();
    errors_.columns[first].second.push_back(l1 / weight);
    errors_.columns[first + 1].second.push_back(std::sqrt(l2 / weight));
    errors_.columns[first + 2].second.push_back(linf);
  }

  Config config_;
  mms::RingMms mms_;
  SolverOptions options_;
  TimeLoopOptions loop_;
  GridGeometry grid_;
  std::unique_ptr<Stepper> stepper_;
  RunOutcome outcome_;

  std::vector<ProbeLine> lines_;
  double point_radius_ = 1.0;
  std::size_t point_tracer_ = 0;
  std::size_t circle_first_ = 0;
  std::vector<double> circle_angle_;
  std::vector<std::vector<double>> circle_simulated_, circle_exact_, circle_spectrum_;
  std::vector<double> point_time_, point_simulated_, point_exact_;
  std::vector<double> output_times_;
  ErrorTable errors_;
};

}  // namespace

std::unique_ptr<SceneCase> build_ring_case(const Config& config) { return std::make_unique<RingCase>(config); }

}  // namespace mpmvv::app
