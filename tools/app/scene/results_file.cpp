#include "results_file.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <numeric>
#include <sstream>

#include <fmt/format.h>

#include "coverage.hpp"
#include "monitor_log.hpp"
#include "probes.hpp"
#include "solver/parallel.hpp"

namespace mpmvv::app {

namespace {

// One value of each row, a dataset as long as the rows.
template <class Row, class Get>
void write_column(h5::Group& g, const std::vector<Row>& rows, const char* name, Get get) {
  std::vector<double> v;
  v.reserve(rows.size());
  for (const Row& r : rows) v.push_back(get(r));
  g.write(name, v, {rows.size()});
}

using MonitorRow = MonitorLog::Row;

template <class Rows>
std::vector<double> flatten(const Rows& rows) {
  std::vector<double> out;
  for (const auto& r : rows) out.insert(out.end(), r.begin(), r.end());
  return out;
}

std::vector<double> flatten_points(const std::vector<Vec2>& points) {
  std::vector<double> out;
  for (const Vec2& p : points) {
    out.push_back(p.x());
    out.push_back(p.y());
  }
  return out;
}

void set_key_attribute(h5::Group& root, const std::string& name, const Value& v) {
  std::visit(
      [&](const auto& x) {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, std::int64_t>) root.set_attribute(name, x);
        else if constexpr (std::is_same_v<T, double>) root.set_attribute(name, x);
        else if constexpr (std::is_same_v<T, std::string>) root.set_attribute(name, x);
        else root.set_attribute(name, x);
      },
      v);
}

// Everything a results file holds, under its root group.
void write_run(h5::Group root, const RunIdentity& request, const Config& config, const SceneCase& scene,
               const RunOutcome& o, const RunHealth& health, Fault fault) {
  // Every scene key as an attribute of its own, then what the run measured.
  for (const KeySpec& k : config.specs()) set_key_attribute(root, k.name, config.value(k.name));
  root.set_attribute("scene", config.scene());
  root.set_attribute("configuration", config.to_toml());
  root.set_attribute("scene_file", request.scene_file);
  {
    std::ifstream in(request.scene_file);
    std::ostringstream text;
    text << in.rdbuf();
    root.set_attribute("scene_file_text", text.str());
  }
  std::string overrides;
  for (const std::string& s : request.overrides) overrides += (overrides.empty() ? "" : "\n") + s;
  root.set_attribute("overrides", overrides);
  root.set_attribute("command_line", request.command_line);
  root.set_attribute("version", request.version);
  if (fault != Fault::none) root.set_attribute("fault_injected", to_string(fault));
  root.set_attribute("threads", std::int64_t(max_threads()));
  const char* wait_policy = std::getenv("OMP_WAIT_POLICY");  // as libgomp read it at load (tools/cli/main.cpp)
  root.set_attribute("omp_wait_policy", std::string(wait_policy ? wait_policy : ""));
  root.set_attribute("status", run_status(o, health));
  const bool lost_at_end = o.completed && health.lost;
  root.set_attribute("failure_reason", lost_at_end ? std::string("solution lost") : o.failure_reason);
  root.set_attribute("failure_detail", lost_at_end ? health.reason : o.failure_detail);
  root.set_attribute("failure_time", lost_at_end ? health.time : o.failure_time);
  root.set_attribute("health", health.lost ? "solution lost" : "healthy");
  root.set_attribute("health_reason", health.reason);
  root.set_attribute("health_time", health.time);
  if (health.reference_position)
    root.set_attribute("health_reference_position",
                       std::vector<double>{health.reference_position->x(), health.reference_position->y()});
  root.set_attribute("failure_step", std::int64_t(o.failure_step));
  root.set_attribute("failure_particle", std::int64_t(o.failure_particle));
  root.set_attribute("time_reached", o.time_reached);
  root.set_attribute("steps", std::int64_t(o.steps));
  root.set_attribute("particle_count", std::int64_t(scene.particle_count()));
  root.set_attribute("particle_steps", std::int64_t(o.particle_steps));
  root.set_attribute("wall_time_s", o.wall_seconds);
  root.set_attribute("solver_time_s", o.wall_seconds - o.forcing_seconds);
  root.set_attribute("forcing_time_s", o.forcing_seconds);
  root.set_attribute("particle_steps_per_second", o.wall_seconds > 0 ? double(o.particle_steps) / o.wall_seconds : 0.0);
  root.set_attribute("h", scene.cell_size());
  root.set_attribute("geometry", to_string(scene.geometry()));
  root.set_attribute("body_force", scene.body_force_kind());
  root.set_attribute("seeding", scene.seeding());
  root.set_attribute("particle_volume", scene.particle_volume());
  root.set_attribute("body_volume", scene.body_volume());
  root.set_attribute("volume_error", scene.particle_volume() / scene.body_volume() - 1.0);
  root.set_attribute("dt", o.dt_first);
  root.set_attribute("dt_min", o.dt_min);
  root.set_attribute("dt_max", o.dt_max);
  root.set_attribute("frequency_measurements", static_cast<double>(o.frequency_measurements));
  // A run continued from restart files: the times it went on from (none for
  // a run in one piece); its wall time is that of the parts that made it.
  root.set_attribute("resumed_at", o.resumed_at);
  scene.write_results(root);
  write_errors(root, scene.errors(), scene.error_description());
  if (const auto m = scene.measurements(); !m.empty()) {
    h5::Group g = root.create_group("measurements");
    for (const auto& [name, value] : m) g.set_attribute(name, value);
  }
}

}  // namespace

const char* run_status(const RunOutcome& o, const RunHealth& health) {
  if (o.completed) return health.lost ? "lost" : "completed";
  return o.failure_reason == kInterrupted ? kInterrupted : "failed";
}

void write_results_file(const std::string& path, const RunIdentity& request, const Config& config,
                        const SceneCase& scene, const RunOutcome& o, const RunHealth& health, Fault fault) {
  h5::File file = h5::File::create(path);
  write_run(file.root(), request, config, scene, o, health, fault);  // the root group closes on return
  file.save();
}

void write_errors(h5::Group& root, const ErrorTable& errors, const std::string& description) {
  h5::Group e = root.create_group("errors");
  e.set_attribute("description", description);
  // Each column's unit, "name unit" a line (norms.hpp: error_unit).
  std::string units;
  for (std::size_t k = 0; k < errors.columns.size() && k < errors.units.size(); ++k)
    units += errors.columns[k].first + " " + (errors.units[k].empty() ? "-" : errors.units[k]) + "\n";
  e.set_attribute("units", units);
  e.write("time", errors.time, {errors.time.size()});
  for (const auto& [name, values] : errors.columns) e.write(name, values, {values.size()});
}

// Each field is written a block of rows at a time from the particle arrays
// (h5::Group::write_rows): staging the whole set would add 12 doubles a
// particle (20 with corner domains) to the run's memory at its last moment.
void write_particles(h5::Group& root, const Particles& P, const std::vector<double>* J) {
  h5::Group g = root.create_group("particles");
  const std::size_t n = P.size();
  // Rows of `per_row` 2-vectors from a field that holds them one row after another.
  auto vectors = [](const auto& field, std::size_t per_row = 1) {
    return [&field, per_row](std::size_t first, std::size_t count, double* out) {
      for (std::size_t k = per_row * first; k < per_row * (first + count); ++k, out += 2) {
        out[0] = field[k].x();
        out[1] = field[k].y();
      }
    };
  };
  auto scalars = [](const auto& value) {
    return [&value](std::size_t first, std::size_t count, double* out) {
      for (std::size_t p = first; p < first + count; ++p) *out++ = value(p);
    };
  };
  g.write_rows("reference_position", {n, 2}, vectors(P.reference_position));
  g.write_rows("position", {n, 2}, vectors(P.position));
  g.write_rows("velocity", {n, 2}, vectors(P.velocity));
  g.write_rows("volume", {n}, scalars([&](std::size_t p) { return P.volume[p]; }));
  g.write_rows("J", {n}, scalars([&](std::size_t p) { return J ? (*J)[p] : determinant(P.deformation_gradient[p]); }));
  g.write_rows("deformation_gradient", {n, 2, 2}, [&](std::size_t first, std::size_t count, double* out) {
    for (std::size_t p = first; p < first + count; ++p)
      for (int k = 0; k < 4; ++k) *out++ = P.deformation_gradient[p](k / 2, k % 2);
  });
  // Corner domains (cpdi_domain = "corners") are whole quadrilaterals, not
  // F_p times the reference half-vectors: store their corners so a reader can
  // draw the domains the transfers used, counter-clockwise from (-1, -1).
  if (P.domain_corner.size() == 4 * n && n > 0) {
    g.write_rows("domain_corners", {n, 4, 2}, vectors(P.domain_corner, 4));
  }
}

void write_particle_index(h5::Group& root, std::size_t count) {
  std::vector<std::int64_t> index(count);
  std::iota(index.begin(), index.end(), std::int64_t{0});
  root.write("particle_index", index, {count});
}

void write_probes(h5::Group& probes, const ProbeRecorder& r) {
  const SceneSetup& setup = r.setup();
  const std::vector<double>& output_times = r.output_times();
  const std::size_t outputs = output_times.size();
  for (std::size_t k = 0; k < setup.lines.size(); ++k) {
    const ProbeLine& line = setup.lines[k];
    h5::Group g = probes.create_group(line.name);
    const char* q = to_string(line.quantity);
    g.set_attribute("quantity", q);
    if (line.reference_angle) g.set_attribute("reference_angle", *line.reference_angle);
    g.set_attribute("description", fmt::format("material points along {}; {} at each output time", line.parameter_name, q));
    const std::size_t n = line.reference.size();
    g.write(line.parameter_name, line.parameter, {n});
    g.write("reference_position", flatten_points(line.reference), {n, 2});
    g.write("time", output_times, {outputs});
    g.write(q, flatten(r.line_records()[k].simulated), {outputs, n});
    g.write(std::string("exact_") + q, flatten(r.line_records()[k].exact), {outputs, n});
  }
  for (std::size_t k = 0; k < setup.points.size(); ++k) {
    const ProbePoint& point = setup.points[k];
    h5::Group g = probes.create_group(point.name);
    const char* q = to_string(point.quantity);
    g.set_attribute("quantity", q);
    g.set_attribute("reference_position", std::vector<double>{point.reference.x(), point.reference.y()});
    if (setup.geometry == Geometry::plane_strain) {
      g.set_attribute("reference_radius", point.reference.norm());
      g.set_attribute("reference_angle", std::atan2(point.reference.y(), point.reference.x()));
    }
    g.set_attribute("description", fmt::format("history of {} at the material point after every step", q));
    g.write("time", r.point_time(), {r.point_time().size()});
    g.write(q, r.point_simulated()[k], {r.point_time().size()});
    g.write(std::string("exact_") + q, r.point_exact()[k], {r.point_time().size()});
  }
  if (setup.circle) {
    h5::Group g = probes.create_group("circle");
    const char* q = to_string(setup.circle->quantity);
    g.set_attribute("quantity", q);
    g.set_attribute("reference_radius", setup.circle->radius);
    g.set_attribute("description", fmt::format("material circle: {} around it at each output time", q));
    g.write("reference_angle", r.circle_angle(), {r.circle_angle().size()});
    g.write("time", output_times, {outputs});
    g.write(q, flatten(r.circle_simulated()), {outputs, r.circle_angle().size()});
    g.write(std::string("exact_") + q, flatten(r.circle_exact()), {outputs, r.circle_angle().size()});
#ifdef MPMVV_HAVE_FFTW
    if (outputs > 0) g.write("error_spectrum", flatten(r.circle_spectrum()), {outputs, r.circle_spectrum().front().size()});
#endif
  }
  if (setup.history) {
    h5::Group g = probes.create_group("history");
    g.set_attribute("description", "scalars of the scene after every step");
    g.write("time", r.history_time(), {r.history_time().size()});
    for (std::size_t k = 0; k < setup.history_names.size(); ++k)
      g.write(setup.history_names[k], r.history_values()[k], {r.history_values()[k].size()});
  }
}

void write_monitors(h5::Group& probes, const MonitorLog& log, bool stable_step) {
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
  g.set_attribute("initial_energy", log.initial_energy());
  auto column = [&](const char* name, auto get) { write_column(g, log.rows(), name, get); };
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
  if (stable_step) {
    column("largest_frequency", [](const MonitorRow& r) { return r.largest_frequency; });
    column("stable_step", [](const MonitorRow& r) { return 2.0 / r.largest_frequency; });
    column("cfl_step", [](const MonitorRow& r) { return r.cfl_step; });
  }
}

void write_coverage(h5::Group& probes, const DomainCoverage& coverage, double cell_size) {
  h5::Group g = probes.create_group("coverage");
  g.set_attribute("description",
                  "how the particles' domains cover the body (tools/app/scene/coverage.hpp): a lattice of "
                  "reference points inside the domains as seeded, carried to each output time by the exact motion "
                  "shifted by the particles' displacement errors interpolated over the reference body, and looked "
                  "up among the current domains; a point no domain contains lies in a hole. "
                  "uncovered_fraction: the share of the sampled material in holes (by reference area); "
                  "inside_fraction: the same for the points whose domain at the start lay away from the body's "
                  "sides (at a side a domain's edge and its centre also part by the error in F); "
                  "largest_hole_area: the current area of the largest 4-connected set of such points on the "
                  "lattice [m^2 per unit depth; of the r-z plane in r-z], resolved to the lattice spacing; "
                  "largest_hole_cells: the same in cells h^2");
  g.set_attribute("lattice_spacing", coverage.spacing());
  g.set_attribute("sampled_points", double(coverage.sampled_points()));
  g.set_attribute("cell_size", cell_size);
  auto column = [&](const char* name, auto get) { write_column(g, coverage.rows(), name, get); };
  column("time", [](const DomainCoverage::Row& r) { return r.time; });
  column("uncovered_fraction", [](const DomainCoverage::Row& r) { return r.uncovered_fraction; });
  column("inside_fraction", [](const DomainCoverage::Row& r) { return r.inside_fraction; });
  column("largest_hole_area", [](const DomainCoverage::Row& r) { return r.largest_hole_area; });
  column("largest_hole_cells",
         [&](const DomainCoverage::Row& r) { return r.largest_hole_area / (cell_size * cell_size); });
}

void write_settling(h5::Group& root, const SettlingWatch& watch, const Settling& s, double end,
                    const ErrorTable& errors) {
  h5::Group g = root.create_group("settling");
  g.set_attribute("description",
                  watch.relaxes()
                      ? "how far the end still is from the static state the damped run relaxes to "
                        "(tools/app/scene/settling.hpp): what the particles (displacement [m], RMS over the body; strain, "
                        "RMS of the symmetric part of F's change) and each error norm read at the end (norms, in "
                        "its unit) moved over the last interval of 1 / decay_rate from kept_time, over "
                        "exp(decay_rate (end - kept_time)) - 1"
                      : "how far the end still is from equilibrium: the Newton correction one more iteration of the "
                        "last load step would make, its mass-weighted RMS over the grid (displacement [m]) and the "
                        "RMS over the body of its strain, from its energy norm (strain)");
  g.set_attribute("method", watch.relaxes() ? "relaxation" : "newton");
  g.set_attribute("displacement", s.displacement);
  g.set_attribute("strain", s.strain);
  if (!watch.relaxes()) return;
  g.set_attribute("decay_rate", watch.decay_rate());
  g.set_attribute("kept_time", watch.kept_at());
  const bool read_at_end = !errors.time.empty() && std::abs(errors.time.back() - end) <= 1e-9 * std::max(1.0, end);
  h5::Group norms = g.create_group("norms");
  for (const auto& [name, value] : watch.norm_settling(end, [&](const std::string& column) {
         const std::vector<double>* values = errors.find(column);
         return read_at_end && values && !values->empty() ? values->back()
                                                          : std::numeric_limits<double>::quiet_NaN();
       }))
    norms.set_attribute(name, value);
}

}  // namespace mpmvv::app
