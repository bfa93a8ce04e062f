// The results file: every run's configuration, outcome and health as
// attributes of its root, then /particles, /errors, /probes (lines, points,
// the circle, histories, the scene's own, the monitors), /settling and
// /measurements. The whole layout is written here; reports/results-format.md
// documents it for the readers (reports/results.py, probes.py).
#pragma once

#include <string>
#include <vector>

#include "solver/io/hdf5.hpp"
#include "solver/model.hpp"
#include "tools/app/config.hpp"
#include "tools/app/fault.hpp"
#include "tools/app/scene/health.hpp"
#include "tools/app/scene/scene.hpp"
#include "tools/app/scene/settling.hpp"

namespace mpmvv::app {

class ProbeRecorder;
class MonitorLog;
class DomainCoverage;

// How the run was asked for, as the root's attributes record it.
struct RunIdentity {
  std::string scene_file;
  std::vector<std::string> overrides;  // "key=value"
  std::string command_line;
  std::string version;
};

// A run that reached its end time with its solution lost (RunHealth) is not
// "completed": its status is "lost", and its failure names the rule.
const char* run_status(const RunOutcome& o, const RunHealth& health);

// Writes the whole file at `path` (HDF5 through solver/io/hdf5.hpp).
void write_results_file(const std::string& path, const RunIdentity& identity, const Config& config,
                        const SceneCase& scene, const RunOutcome& o, const RunHealth& health, Fault fault);

// The groups a scene writes (SceneCase::write_results).
// `J`: each particle's J when F does not give it (an external program's J or
// volumes); null: det F.
void write_particles(h5::Group& root, const Particles& particles, const std::vector<double>* J = nullptr);
// /particle_index: 0 .. count - 1, the particles as cells of one vertex each
// for the .xmf sidecar (xdmf_file.hpp); count the most particles any group holds.
void write_particle_index(h5::Group& root, std::size_t count);
void write_errors(h5::Group& root, const ErrorTable& errors, const std::string& description);
void write_probes(h5::Group& probes, const ProbeRecorder& recorder);
void write_monitors(h5::Group& probes, const MonitorLog& log, bool stable_step);
// /probes/coverage: the holes between the particles' domains at each output
// time (coverage.hpp), with the cell size h they are counted in.
void write_coverage(h5::Group& probes, const DomainCoverage& coverage, double cell_size);
// A static scene's distance from its static state at the end time `end`
// (settling.hpp), `at_end` measured there.
void write_settling(h5::Group& root, const SettlingWatch& watch, const Settling& at_end, double end,
                    const ErrorTable& errors);

}  // namespace mpmvv::app
