#include "external_case.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numeric>
#include <string_view>

#include <fmt/format.h>

#include "monitor_log.hpp"
#include "norms.hpp"
#include "particle_output.hpp"
#include "probes.hpp"
#include "results_file.hpp"
#include "seeding.hpp"
#include "setup.hpp"
#include "solver/parallel.hpp"
#include "tools/app/installation.hpp"
#include "tracer_interpolation.hpp"

namespace mpmvv::app {

namespace {

namespace fs = std::filesystem;
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

// Whether an output's fields give the norm of kParticleNorms (norms.hpp:
// particle_norms computes all of them; a norm of a field the program did not
// write is left out). The displacement norms need the positions only.
bool norm_given(std::string_view norm, const OutputFields& f) {
  if (norm == "particle_pressure_L2") return f.stress;
  if (norm == "particle_deformation_L2") return f.deformation_gradient;
  if (norm == "particle_velocity_L2") return f.velocity;
  return true;
}

std::string fields_text(const OutputFields& f) {
  std::string s = "reference_position, position, reference_volume";
  for (const auto& [given, name] : {std::pair{f.velocity, "velocity"}, {f.stress, "stress"},
                                    {f.deformation_gradient, "deformation_gradient"}, {f.J, "J"},
                                    {f.volume, "volume"}, {f.mass, "mass"}, {f.tracers, "tracer_position"}})
    if (given) s += fmt::format(", {}", name);
  return s;
}

class ExternalCase final : public SceneCase {
 public:
  ExternalCase(const Config& config, const SceneType& type, ExternalProgram program)
      : config_(config), setup_(type.setup(config)), loop_(time_loop_options(config)), probes_(setup_),
        program_(std::move(program)) {
    if (setup_.run_refused) config_.reject(setup_.run_refused->key, setup_.run_refused->why);
    const char* why = !setup_.exact_motion                 ? "has no exact motion to measure particles against"
                      : !setup_.extra_error_names.empty() ? "measures errors of its own from mpmvv's solver"
                      : setup_.settling                   ? "settles to a static state, which mpmvv's solver judges"
                      : setup_.geometry != Geometry::plane_strain ? "is r-z; external programs are read in plane strain"
                                                                  : nullptr;
    if (why)
      config_.reject("external_command", fmt::format("scene '{}' {}: run an external program on a scene with an exact "
                                                     "motion in plane strain (mpmvv scenes)",
                                                     config_.scene(), why));
    // The template's names, checked before anything runs.
    expand_command(program_.command, config_, external_files("case.h5", program_.format), "mpmvv", 1);
  }

  void set_results_path(const std::string& path) override { results_path_ = path; }
  bool external() const override { return true; }
  void inject(Fault) override {}  // the faults are mpmvv's solver's; a suite's crash and hang act before run()

  RunOutcome run(const ProgressSink& progress, const RestartPlan& restart) override {
    (void)restart;  // mpmvv keeps no state of another program's run: a restart starts it again
    if (results_path_.empty()) throw std::logic_error("an external case runs with its results path set");
    files_ = external_files(results_path_, program_.format);
    std::vector<Vec2> tracers;
    probes_.seed_tracers(tracers);
    write_external_input(files_, config_, loop_.output_times, probes_.tracer_references(), tracers, program_.format);
    std::error_code ec;
    fs::remove_all(files_.output, ec);  // what an earlier run left is not this run's
    command_ = expand_command(program_.command, config_, files_, self_executable(), max_threads());
    double told = 0.0;
    const auto tick = [&](double s) {
      if (progress && s - told >= 10.0) {
        told = s;
        fmt::print(stderr, "external program running: {:.0f} s (its output: {})\n", s, files_.log);
      }
    };
    RunOutcome o;
    try {
      end_ = run_program(command_, files_.log, program_.timeout, tick);
    } catch (const std::runtime_error& e) {  // it could not be started
      return finish(o, 0, "external program failed", e.what());
    }
    o.wall_seconds = end_.seconds;
    const ParticleOutput output(files_.output, program_.format, loop_.output_times, program_.names, program_.stress_order);
    const std::size_t count = loop_.output_times.size();
    std::size_t k = 0;
    for (; k < count; ++k) {
      std::optional<OutputState> state;
      try {
        state = output.read(k, tracers.size());
      } catch (const std::exception& e) {  // ParticleOutputError, and HDF5's own
        return finish(o, k, "malformed output", e.what());
      }
      if (!state) break;
      if (k == 0) start(*state);
      else if (state->fields != fields_)
        return finish(o, k, "malformed output",
                      fmt::format("output {} holds {}; output 0 held {}", k, fields_text(state->fields),
                                  fields_text(fields_)));
      if (interpolated_tracers_) {
        try {
          state->tracers = interpolated_tracers(state->P.reference_position, state->P.position,
                                                state->P.reference_volume, probes_.tracer_references());
        } catch (const TracerInterpolationError& e) {
          return finish(o, k, "malformed output", fmt::format("output {}: {}", k, e.what()));
        }
      }
      record(k, *state);
      output_spacing_ = k == 0 ? state->output_spacing : std::max(output_spacing_, state->output_spacing);
      o.time_reached = loop_.output_times[k];
      o.outputs_written = k + 1;
      auto finite = [](const std::vector<Vec2>& x) {
        return std::all_of(x.begin(), x.end(), [](const Vec2& v) { return v.allFinite(); });
      };
      const bool particles_finite = finite(state->P.position), tracers_finite = finite(state->tracers);
      last_ = std::move(state->P);
      last_J_ = std::move(state->J);
      if (!particles_finite || !tracers_finite)
        return finish(o, k, "nan", fmt::format("a {} is not a number at t = {:.6g} s",
                                               particles_finite ? "tracer position (tracer_position)"
                                                                : "particle position",
                                               loop_.output_times[k]));
    }
    if (end_.stopped)  // a suite runs an interrupted case again
      return finish(o, k, kInterrupted, fmt::format("the external program was {}", end_.describe()));
    if (!end_.succeeded() || k < count) {
      std::string detail = end_.succeeded() ? "" : end_.describe();
      if (k < count)
        detail += fmt::format("{}no output for t = {:.6g} s at {}", detail.empty() ? "" : ", ", loop_.output_times[k],
                              files_.output);
      detail += end_.log_tail.empty() ? "; it printed nothing" : "; its last lines: " + end_.log_tail;
      return finish(o, k, end_.succeeded() ? "missing output" : "external program failed", detail);
    }
    o.completed = true;
    return o;
  }

  double cell_size() const override { return setup_.grid.h; }
  std::size_t particle_count() const override { return last_.size(); }
  Geometry geometry() const override { return setup_.geometry; }
  std::string body_force_kind() const override { return "the external program's own"; }
  std::string seeding() const override { return "the external program's own"; }
  double particle_volume() const override {
    return std::accumulate(last_.reference_volume.begin(), last_.reference_volume.end(), 0.0);
  }
  double body_volume() const override { return exact_body_volume(setup_); }
  const ErrorTable& errors() const override { return errors_; }
  std::string error_description() const override {
    return fmt::format("{}; computed by mpmvv from the external program's particles (given: {}{}; "
                       "reports/external-format.md)",
                       norm_definitions(), fields_text(fields_),
                       interpolated_tracers_ ? "; the probe lines' tracers placed by mpmvv from the particles" : "");
  }
  std::optional<double> exact_signal_fraction(const std::string& norm, double time) const override {
    return app::exact_signal_fraction(setup_, loop_, norm, time);
  }
  // The lines' L1 and the particle norms, those the program's output allows (start()).
  std::vector<std::string> possible_error_columns() const override {
    std::vector<std::string> names;
    for (const ProbeLine& line : setup_.lines) names.push_back("L1_" + line.name);
    names.insert(names.end(), std::begin(kParticleNorms), std::end(kParticleNorms));
    return names;
  }

  // J's rule where the program gave F, J or volumes; the energy balance is
  // not known (NaN in the samples: judge_health skips it).
  RunHealth health() const override {
    const double J_factor = j_given() ? config_.real("health_J_factor") : std::numeric_limits<double>::infinity();
    return judge_health(samples_, errors_, {J_factor, config_.real("health_energy_loss_factor"), true}, motion_);
  }

  void write_results(h5::Group& root) const override {
    write_particles(root, last_, !fields_.deformation_gradient && last_J_.size() == last_.size() ? &last_J_ : nullptr);
    write_particle_index(root, last_.size());
    h5::Group probes = root.create_group("probes");
    write_probes(probes, probes_);
    h5::Group g = root.create_group("external");
    g.set_attribute("description",
                    "the external program this case ran in place of mpmvv's solver (external_command): the command "
                    "as run, how it ended, what it wrote (reports/external-format.md); the norms and the health "
                    "verdict are mpmvv's, from its particles; the energy balance is not known");
    g.set_attribute("command_template", program_.command);
    g.set_attribute("command", command_);
    g.set_attribute("format", program_.format);
    g.set_attribute("names", config_.text("external_names"));
    g.set_attribute("stress_order", config_.text("external_stress_order"));
    g.set_attribute("output", files_.output);
    g.set_attribute("input", files_.input);
    g.set_attribute("log", files_.log);
    g.set_attribute("ended", end_.describe());
    g.set_attribute("exit_status", std::int64_t(end_.exit_status));
    g.set_attribute("wall_time_s", end_.seconds);
    g.set_attribute("log_tail", end_.log_tail);
    g.set_attribute("fields", fields_text(fields_));
    g.set_attribute("tracers", fields_.tracers          ? "written by the program (tracer_position)"
                               : interpolated_tracers_ ? tracer_interpolation_description()
                                                       : "none: the scene has no probes");
    g.set_attribute("J_rule", j_given() ? "applied" : "not applied: the program gave no F, J or volume");
    // The report's round-off floor counts this rounding (reports/orders.py: OUTPUT_SPACING_UNITS).
    g.set_attribute("output_spacing", output_spacing_);
    g.write("output_time", program_time_, {program_time_.size()});
  }

 private:
  bool j_given() const { return fields_.deformation_gradient || fields_.J; }

  // The columns from what the first output holds; the time integral's first
  // point and the whole motion (health.hpp) from its particles.
  void start(const OutputState& first) {
    fields_ = first.fields;
    errors_ = ErrorTable{};
    // A program that follows no tracers gets them placed from its particles.
    interpolated_tracers_ = !fields_.tracers && !probes_.tracer_references().empty();
    if (fields_.tracers || interpolated_tracers_)
      for (const ProbeLine& line : setup_.lines)
        errors_.add_column("L1_" + line.name, error_unit("L1_" + line.name, setup_.lines));
    for (std::size_t c = 0; c < std::size(kParticleNorms); ++c)
      if (norm_given(kParticleNorms[c], fields_))
        errors_.add_column(kParticleNorms[c], error_unit(kParticleNorms[c], setup_.lines));
    // The exact state at t = 0, as mpmvv seeds it (case.cpp: initial).
    Particles at_start = first.P;
    for (std::size_t p = 0; p < at_start.size(); ++p)
      at_start.position[p] = setup_.solution->position(at_start.reference_position[p], 0.0);
    const DisplacementSums d = displacement_sums(at_start, *setup_.solution, 0.0);
    integrated_ = {};
    integrated_.add(0.0, d.l2, d.exact2);
    // The whole motion between the output times, sampled at 1000 times.
    motion_ = 0.0;
    for (int i = 1; i <= 1000; ++i)
      motion_ = std::max(motion_, sampled_exact_motion(loop_.end_time * i / 1000.0, first.P, *setup_.solution));
  }

  void record(std::size_t k, OutputState& s) {
    errors_.time.push_back(loop_.output_times[k]);
    program_time_.push_back(s.time);
    std::size_t column = 0;
    if (fields_.tracers || interpolated_tracers_)
      for (double l1 : probes_.at_output(s.time, s.tracers)) errors_.columns[column++].second.push_back(l1);
    double spin = 0.0;
    const std::vector<double> norms =
        particle_norms(s.P, *setup_.solution, setup_.geometry, s.time, integrated_, j_ratio_, spin);
    for (std::size_t c = 0; c < norms.size(); ++c)
      if (norm_given(kParticleNorms[c], fields_)) errors_.columns[column++].second.push_back(norms[c]);
    // J / J_exact from J or the volumes where F was not given.
    if (!fields_.deformation_gradient && fields_.J)
      for (std::size_t p = 0; p < s.P.size(); ++p) {
        const mms::ExactFields f = setup_.solution->state(s.P.reference_position[p], s.time);
        j_ratio_[p] = s.J[p] / (determinant(f.deformation_gradient) * f.hoop_stretch);
      }
    JRatioRange range{1.0, 1.0, Vec2::Constant(nan)};
    if (j_given()) range = j_ratio_range(j_ratio_, s.P.reference_position);
    samples_.push_back({loop_.output_times[k], range.min, range.max, range.worst_reference, nan, nan});
  }

  RunOutcome finish(RunOutcome o, std::size_t k, const std::string& reason, const std::string& detail) const {
    o.completed = false;
    o.failure_reason = reason;
    o.failure_detail = detail;
    o.failure_time = k < loop_.output_times.size() ? loop_.output_times[k] : o.time_reached;
    return o;
  }

  Config config_;
  SceneSetup setup_;
  TimeLoopOptions loop_;
  ProbeRecorder probes_;
  ExternalProgram program_;
  std::string results_path_, command_;
  ExternalFiles files_;
  ProgramEnd end_;
  OutputFields fields_;
  Particles last_;            // the particles of the last output read
  std::vector<double> last_J_;  // their J from J or the volumes (empty when not given)
  ErrorTable errors_;
  TimeIntegral integrated_;
  std::vector<double> j_ratio_, program_time_;
  double output_spacing_ = 0.0;  // the coarsest of the outputs' (OutputState::output_spacing)
  bool interpolated_tracers_ = false;  // the program wrote none: tracer_interpolation.hpp places them
  std::vector<HealthSample> samples_;
  double motion_ = 0.0;
};

}  // namespace

std::unique_ptr<SceneCase> make_external_case(const Config& config, const SceneType& type,
                                              const ExternalProgram& program) {
  return std::make_unique<ExternalCase>(config, type, program);
}

}  // namespace mpmvv::app
