// A scene: geometry, material, loading, the exact solution and the probes
// where error is measured. It names the solver stages it needs; the rest are
// absent from its run.
#pragma once

#include <functional>
#include <iosfwd>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tools/app/config.hpp"
#include "tools/app/fault.hpp"
#include "health.hpp"
#include "solver/io/hdf5.hpp"
#include "solver/model.hpp"
#include "solver/time_loop.hpp"

namespace mpmvv::app {

// Error norms per output time, one named column per norm.
struct ErrorTable {
  std::vector<double> time;
  std::vector<std::pair<std::string, std::vector<double>>> columns;
  std::vector<std::string> units;  // one a column (norms.hpp: error_unit); "1" for a relative error

  const std::vector<double>& column(const std::string& name) const;  // throws when there is none
  const std::vector<double>* find(const std::string& name) const;     // null when there is none
  std::vector<double>& add_column(const std::string& name, const std::string& unit = "");

  template <class Archive>
  void persist(Archive& a) {
    a.field("time", time);
    a.field("columns", columns);
    a.field("units", units);
  }
};

// A restart file for SceneCase::run (solver/time_loop.hpp: Checkpoints).
struct RestartPlan {
  std::string path;  // where the state is saved and read; empty: no restart file
  double every_seconds = 0.0;                                   // wall time between saves; 0: only on an early stop
  double pause_at = std::numeric_limits<double>::infinity();  // stop, saving the state, from this time on
  bool resume = false;  // go on from the state at `path` (whose identity the caller has checked)
  // Attributes of the file's root that say which run the state belongs to
  // (configuration, build, threads), for the caller to check before a resume.
  std::vector<std::pair<std::string, std::string>> identity;
  // Told of each save (`failed`: a save that failed, which the run goes on
  // without).
  std::function<void(const std::string& message, bool failed)> tell;
};

// What a run of a case will take, known before it runs: its particles (the
// body's area over the particle spacing squared) and its steps (end time over
// a fixed step, or over the step at rest, cfl h / c0 with the material's
// p-wave speed c0: a run whose waves speed up takes more, which
// suite/estimate.hpp measures).
struct WorkEstimate {
  std::size_t particles = 0;
  long long steps = 0;
  bool implicit = false;  // steps are load steps, each a Newton solve
};

// One configured case of a scene, ready to run.
class SceneCase {
 public:
  virtual ~SceneCase() = default;
  // Steps the scene to its end time (or to the step that stopped it), saving
  // and going on from a restart file as `restart` says.
  virtual RunOutcome run(const ProgressSink& progress, const RestartPlan& restart = {}) = 0;
  // A deliberate fault (tools/app/fault.hpp), set before run().
  virtual void inject(Fault fault) = 0;
  // Where the results file will be written, set before run(): a case that
  // writes files of its own beside it (an external program's) names them from it.
  virtual void set_results_path(const std::string& /*path*/) {}
  // Whether another program made the run (external_command): it took no
  // steps of mpmvv's, and its method is its own.
  virtual bool external() const { return false; }
  // Cell size, for the results file.
  virtual double cell_size() const = 0;
  virtual std::size_t particle_count() const = 0;
  // The work of the run before it runs (`mpmvv suite --list`); none where the
  // case cannot say (another program's run).
  virtual std::optional<WorkEstimate> estimate() const { return std::nullopt; }
  virtual Geometry geometry() const = 0;
  // How the body force is evaluated ("derived", "closed form"), or "none".
  virtual std::string body_force_kind() const = 0;
  // How particles were seeded ("exact", "centre"), their total reference
  // volume and the body's exact volume (NaN when not known exactly).
  virtual std::string seeding() const = 0;
  virtual double particle_volume() const = 0;
  virtual double body_volume() const = 0;
  // Scalars the scene measures at the end (name, value), for /measurements.
  virtual std::vector<std::pair<std::string, double>> measurements() const { return {}; }
  // Writes particles and probes under `root` (the errors are written from errors()).
  virtual void write_results(h5::Group& root) const = 0;
  virtual const ErrorTable& errors() const = 0;
  // The health verdict of the run just made (health.hpp).
  virtual RunHealth health() const = 0;
  // What the error columns mean, stored with them.
  virtual std::string error_description() const = 0;
  // What the exact solution gives the error column `norm` to measure at output
  // time `time`, as a fraction of its largest over the output times (the mean
  // |exact| on an L1_<line> norm's line, the RMS exact displacement for the
  // particle norms; as reports/scales.py: exact_signal_fraction reads it
  // from a results file). None where the scene cannot say. Known before the
  // run: the suite loader warns of a read where the motion is nearly absent.
  // A NaN time is the end time.
  virtual std::optional<double> exact_signal_fraction(const std::string& /*norm*/, double /*time*/) const {
    return std::nullopt;
  }
  // Every /errors column a run of this case can write (norms.hpp:
  // error_columns), so that an expectation naming another is refused before
  // anything runs; empty where the scene cannot say.
  virtual std::vector<std::string> possible_error_columns() const { return {}; }
};

struct SceneSetup;  // setup.hpp

// A scene: its name, what it is, its keys, and what is particular to it.
struct SceneType {
  std::string name;
  std::string summary;
  std::vector<KeySpec> (*keys)();
  // Checks the keys that depend on each other (throws ConfigError naming the
  // key) and sets the scene up: body, material, exact solution, probes, loads.
  SceneSetup (*setup)(const Config&);
  // A case of the scene, ready to run (case.cpp); throws as `setup` does.
  std::unique_ptr<SceneCase> build(const Config& config) const;
};

// Every scene (tools/app/scenes/registry.cpp), and the one of a name (null: none).
const std::vector<SceneType>& scene_types();
const SceneType* find_scene_type(const std::string& name);

// Keys every solver-driven scene shares: method, scheme, resolution, time.
std::vector<KeySpec> solver_keys(std::int64_t default_cells, double default_end_time,
                                 std::vector<double> default_output_times);
SolverOptions solver_options(const Config& config);
// The output times that lie in (0, end_time], with end_time always last.
TimeLoopOptions time_loop_options(const Config& config);

// The error table a person reads at the end of a run.
void print_error_table(std::ostream& out, const ErrorTable& errors);

// Prints the measurements, one per line.
void print_measurements(std::ostream& out, const std::vector<std::pair<std::string, double>>& measurements);

}  // namespace mpmvv::app
