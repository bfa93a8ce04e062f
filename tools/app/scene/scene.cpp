#include "scene.hpp"

#include <algorithm>
#include <cmath>
#include <ostream>

#include <fmt/ostream.h>

#include <fmt/format.h>

#include "external_program.hpp"

namespace mpmvv::app {

std::vector<KeySpec> solver_keys(std::int64_t default_cells, double default_end_time,
                                 std::vector<double> default_output_times) {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<KeySpec> keys = {
      {"method", KeyKind::text, std::string("cpdi"), "shape functions: linear (standard MPM), gimp (uGIMP), cpdi, cpdi-exact (CPDI domains "
       "integrated exactly over the cells they cross), bspline and bspline-cubic (point particles on the grid's "
       "quadratic or cubic B-splines; plane strain, explicit, the body half a cell or a cell clear of the walls)",
       -inf, inf, false, false, {"linear", "gimp", "cpdi", "cpdi-exact", "bspline", "bspline-cubic"}},
      {"scheme", KeyKind::text, std::string("usl"), "stress update: usl (update stress last), usf (first), musl (modified USL)",
       -inf, inf, false, false, {"usl", "usf", "musl"}},
      {"time_integration", KeyKind::text, std::string("central-difference"),
       "central-difference (velocities at half steps, second order) or symplectic-euler (velocities at whole "
       "steps, first order); both use eqs. 1.72 and 1.76",
       -inf, inf, false, false, {"central-difference", "symplectic-euler"}},
      {"dilatation", KeyKind::text, std::string("particle"),
       "particle: each particle keeps its own det F; cell-averaged: each takes its cell's mean dilatation after every "
       "deformation update (eqs. 1.82-1.84 of the Vaango manual), the remedy for volumetric locking; node-smoothed: "
       "each takes the mean dilatation of the nodes it reaches, with the method's weights (removes a J that varies "
       "from particle to particle, which the grid cannot push back on)",
       -inf, inf, false, false, {"particle", "cell-averaged", "node-smoothed"}},
      {"formulation", KeyKind::text, std::string("updated"),
       "updated: the grid is fixed in space and the particles move through it (the usual MPM); total: the grid is "
       "the body's reference configuration and each particle is weighed at its reference position for the whole "
       "run (total Lagrangian MPM; every method, weighed at the reference positions and domains, plane strain, no contact): no "
       "cell crossing, and the linearized "
       "step of a stressed body stays symmetric (solver/shape/total_lagrangian.hpp)",
       -inf, inf, false, false, {"updated", "total"}},
      {"velocity_transfer", KeyKind::text, std::string("flip"),
       "how particles take their velocity back from the grid: flip (each keeps its own and adds the grid's "
       "acceleration, eq. 1.76; what the grid cannot hold stays on the particles) or apic (each takes the grid's "
       "velocity and its gradient C_p and maps back the affine field v_p + C_p (x - x_p): affine motion is kept, "
       "the rest is damped every step; updated formulation, plane strain; solver/model.hpp)",
       -inf, inf, false, false, {"flip", "apic"}},
      {"split_domains_beyond", KeyKind::real, 0.0,
       "cpdi, and cpdi-exact with corner domains: after a step, a particle whose domain is longer than this many "
       "cells along one of its vectors is replaced by its two halves along it (0: never); keeps the corner "
       "interpolation of CPDI within a few cells under large shear",
       0.0, 1000.0, false, false},
      {"min_domain_angle", KeyKind::real, 0.0,
       "cpdi only, updated formulation: after a step, a domain whose sides meet at less than this angle [degrees] "
       "is turned, keeping its centre, area and second moment of area, until they meet at this angle (0: never; "
       "solver/domain_angle.hpp); bounds the CPDI gradient, which grows as 1 / sin of that angle, under large shear",
       0.0, 89.0, false, false},
      {"cpdi_domain", KeyKind::text, std::string("convected"),
       "cpdi and cpdi-exact, updated formulation, plane strain: convected (each domain the parallelogram F_p "
       "diag(l_p), eq. 1.97) or corners (each domain the quadrilateral of four corners moved with the grid velocity, "
       "as the particles are: neighbours keep sharing their corners, so the domains tile the body however it shears; "
       "solver/domain_corners.hpp; cpdi-exact integrates the hats over the quadrilateral itself)",
       -inf, inf, false, false, {"convected", "corners"}},
      {"bulk_viscosity", KeyKind::real, 0.0,
       "linear artificial bulk viscosity C0 (eq. 1.66 of the Vaango manual; 0.2 is typical, 0: none): a stress "
       "rho l C0 c tr(d) I, l the particle's thinnest width (at most h), that damps the particles' dilatation rate in "
       "compression and expansion",
       0.0, 10.0, false, false},
      {"bulk_viscosity_quadratic", KeyKind::real, 0.0,
       "quadratic artificial bulk viscosity C1 (eq. 1.66; 2.0 is typical, 0: none): adds rho l^2 C1 |tr d| tr(d) I",
       0.0, 100.0, false, false},
      {"cells", KeyKind::integer, default_cells, "cells across the domain along each axis", 4, 20000},
      {"particles_per_direction", KeyKind::integer, std::int64_t(2),
       "particles per cell along each axis (2 means 4 per cell in 2D)", 1, 16},
      {"cfl", KeyKind::real, 0.3,
       "time step as a fraction of h / max(wave speed + particle speed) (with time_step = \"stable\": of the "
       "measured stable step 2 / omega_max), the wave speed raised where a sheared CPDI "
       "domain's gradients exceed the grid basis's own (solver/stages.hpp: scan_particles); an undeformed 2D grid is "
       "stable to about 1/sqrt(2)",
       0.0, 1.0, true, false},
      {"time_step", KeyKind::text, std::string("cfl"),
       "cfl: dt = cfl h / max(wave speed + particle speed); stable: dt = cfl 2 / omega_max, the fraction cfl of the "
       "stable step of central differences, omega_max measured by 20 power iterations on the step's linearization "
       "every 50 steps (sooner when the particles' wave-speed bound grows by 10 %) and extrapolated in between (formulation = \"total\" only, whose linearization is "
       "symmetric; solver/time_loop.hpp): a particle-wise wave speed overstates the grid's largest frequency where "
       "a few particles are strongly compressed",
       -inf, inf, false, false, {"cfl", "stable"}},
      {"end_time", KeyKind::real, default_end_time, "time at which the run stops [s]", 0.0, inf, true},
      {"output_times", KeyKind::real_list, std::move(default_output_times),
       "times at which probes and errors are recorded [s]; later than end_time are dropped, end_time is always one",
       0.0, inf, true},
      {"particle_fields", KeyKind::text, std::string("end"),
       "end: the particles' state at the end only (/particles); outputs: also their position, displacement, "
       "velocity, J, stress, F and displacement error at every output time (/snapshots, about 120 bytes a particle "
       "and output), which ParaView animates through the results file's .xmf sidecar",
       -inf, inf, false, false, {"end", "outputs"}},
      {"stable_step_iterations", KeyKind::integer, std::int64_t(0),
       "power iterations that measure, at every output time, the largest frequency omega_max of the grid's motion "
       "linearized about the run's state, and so its stable step 2 / omega_max, beside the step the CFL rule takes "
       "(monitors largest_frequency, stable_step, cfl_step; explicit steps only; 0: not measured, 30 is plenty; each "
       "iteration costs about two transfers)",
       0, 10000},
      {"coverage_samples", KeyKind::integer, std::int64_t(0),
       "lattice points per particle spacing along each axis with which the body is sampled to find the holes "
       "between the particles' domains, where no domain covers the material (tools/app/scene/coverage.hpp; "
       "/probes/coverage: the share of the material in holes and the largest hole's area, at every output time; "
       "methods with domains, updated formulation, scenes with an exact motion; 0: not measured; 2 is plenty, "
       "and costs about 0.8 us a particle at each output time, 16 bytes a particle held, about 120 more while "
       "it measures)",
       0, 16},
      // Defaults from the ring runs on record (cpdi, cpdi-exact, uGIMP, B-splines;
      // 30-1200 cells, soft and stiff): runs that converge reach J / J_exact
      // 0.116-3.35, error over motion 0.15 and energy lost 0.44 at most; runs
      // whose solution is gone reach J 0.002-0.0064 or 9-26 and error over
      // motion 1.7-1.8 (suites/ring-sandia.toml, suites/stiff-vortex.toml).
      {"health_J_factor", KeyKind::real, 20.0,
       "the run's solution is called lost (status \"lost\") when at an output time a particle's J / J_exact, J = det F, "
       "leaves [1 / health_J_factor, health_J_factor] (J_exact = 1 where the scene has no exact motion); also when a "
       "displacement error norm exceeds the largest exact displacement of the run or is not a number, and when "
       "energy is lost beyond health_energy_loss_factor",
       1.0, inf, true},
      {"health_energy_loss_factor", KeyKind::real, 1.0,
       "the run's solution is called lost when the energy it lost to the method (kinetic plus strain energy less "
       "their start, less the work done on it, when negative) exceeds this factor times the larger of the energy it "
       "started with and the largest work done on it",
       0.0, inf, true},
      {"energy_blowup_factor", KeyKind::real, 10.0,
       "at an output time the run stops with 'energy blow-up' when the energy it made from nothing (kinetic plus "
       "strain energy less their start, less the work done on it) exceeds this factor times the larger of the energy "
       "it started with and the largest work done on it",
       0.0, inf, true},
  };
  for (KeySpec& k : external_program_keys()) keys.push_back(std::move(k));
  return keys;
}

SolverOptions solver_options(const Config& c) {
  SolverOptions o;
  const std::string& m = c.text("method");
  o.method = m == "linear"   ? Method::linear
             : m == "gimp"   ? Method::gimp
             : m == "cpdi"   ? Method::cpdi
             : m == "bspline" ? Method::bspline
             : m == "bspline-cubic" ? Method::bspline_cubic
                             : Method::cpdi_exact;
  const std::string& s = c.text("scheme");
  o.scheme = s == "usf" ? Scheme::usf : s == "musl" ? Scheme::musl : Scheme::usl;
  const std::string& d = c.text("dilatation");
  o.dilatation = d == "cell-averaged"   ? Dilatation::cell_averaged
                 : d == "node-smoothed" ? Dilatation::node_smoothed
                                        : Dilatation::particle;
  o.formulation = c.text("formulation") == "total" ? Formulation::total : Formulation::updated;
  o.velocity_transfer = c.text("velocity_transfer") == "apic" ? VelocityTransfer::apic : VelocityTransfer::flip;
  o.split_domains_beyond = c.real("split_domains_beyond");
  o.min_domain_angle = c.real("min_domain_angle");
  o.cpdi_domain = c.text("cpdi_domain") == "corners" ? CpdiDomain::corners : CpdiDomain::convected;
  o.bulk_viscosity_linear = c.real("bulk_viscosity");
  o.bulk_viscosity_quadratic = c.real("bulk_viscosity_quadratic");
  return o;
}

TimeLoopOptions time_loop_options(const Config& c) {
  TimeLoopOptions o;
  o.end_time = c.real("end_time");
  o.cfl = c.real("cfl");
  if (c.text("time_step") == "stable") {
    if (c.text("formulation") != "total")
      c.reject("time_step", fmt::format("\"stable\" tracks omega_max by power iteration, which needs the symmetric "
                                        "linearization of formulation = \"total\" (formulation = \"{}\" from {})",
                                        c.text("formulation"), c.origin("formulation").source));
    o.step_rule = TimeStepRule::stable;
  }
  o.time_integration = c.text("time_integration") == "symplectic-euler" ? TimeIntegration::symplectic_euler
                                                                       : TimeIntegration::central_difference;
  const std::vector<double>& times = c.reals("output_times");
  for (std::size_t i = 1; i < times.size(); ++i)
    if (!(times[i] > times[i - 1]))
      c.reject("output_times", fmt::format("must be strictly increasing ({} follows {})", times[i], times[i - 1]));
  for (double t : times)
    if (t < o.end_time) o.output_times.push_back(t);
  o.output_times.push_back(o.end_time);
  return o;
}

const std::vector<double>* ErrorTable::find(const std::string& name) const {
  for (const auto& [n, values] : columns)
    if (n == name) return &values;
  return nullptr;
}

const std::vector<double>& ErrorTable::column(const std::string& name) const {
  if (const std::vector<double>* values = find(name)) return *values;
  throw std::out_of_range("no error column '" + name + "'");
}

std::vector<double>& ErrorTable::add_column(const std::string& name, const std::string& unit) {
  columns.emplace_back(name, std::vector<double>{});
  units.push_back(unit);
  return columns.back().second;
}

void print_error_table(std::ostream& out, const ErrorTable& errors) {
  if (errors.time.empty()) return;  // a case that ended before its first output has no table to print
  fmt::print(out, "{:>8}", "t [s]");
  for (const auto& [name, values] : errors.columns) fmt::print(out, " {:>14}", name);
  fmt::print(out, "\n{:>8}", "");
  // Under each name its unit; "[1]" marks a ratio (a relative error, F's error).
  for (std::size_t k = 0; k < errors.columns.size(); ++k)
    fmt::print(out, " {:>14}", k < errors.units.size() && !errors.units[k].empty() ? "[" + errors.units[k] + "]" : "");
  fmt::print(out, "\n");
  for (std::size_t k = 0; k < errors.time.size(); ++k) {
    fmt::print(out, "{:>8.4g}", errors.time[k]);
    for (const auto& [name, values] : errors.columns) fmt::print(out, " {:>14.4e}", values[k]);
    fmt::print(out, "\n");
  }
}

void print_measurements(std::ostream& out, const std::vector<std::pair<std::string, double>>& measurements) {
  for (const auto& [name, value] : measurements) fmt::print(out, "{:<28} {:.9g}\n", name, value);
}

}  // namespace mpmvv::app
