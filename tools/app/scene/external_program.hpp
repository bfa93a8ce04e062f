// Another MPM code run in place of mpmvv's solver (external_command): the
// command line made from its template, the input files the harness writes
// for it, and the program run under a time-out. What it writes back is read
// by particle_output.hpp; the case around both is external_case.cpp.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "solver/tensor.hpp"
#include "tools/app/config.hpp"
#include "tools/app/scene/particle_output.hpp"

namespace mpmvv::app {

// The keys of every solver-driven scene that name an external program.
std::vector<KeySpec> external_program_keys();

struct ExternalProgram {
  std::string command;  // the template, as configured
  std::string format;   // "hdf5", "csv" or "vtk": what the program writes at {output}
  double timeout = 0.0;  // seconds; 0: none of its own
  OutputNames names;    // external_names: how its files spell mpmvv's items
  StressOrder stress_order = kVtkStressOrder;  // external_stress_order: a 6-component VTK stress's order
};
// The program `config` names, or none (external_command = "": mpmvv's own
// solver). A malformed external_names or external_stress_order is refused
// (ConfigError naming it), and so is either without a command.
std::optional<ExternalProgram> external_program(const Config& config);

// Where a case's files go (absolute paths), beside its results file RESULTS.h5: RESULTS.input.json
// and RESULTS.scene.toml (the inputs), RESULTS.external.h5 or the folder
// RESULTS.external/ (the program's particle output), RESULTS.external.log
// (what it printed).
struct ExternalFiles {
  std::string input, scene, output, log;
};
ExternalFiles external_files(const std::string& results_path, const std::string& format);

// The command line: each {name} of the template replaced by the value of the
// key of that name (as --describe prints it) or by one of {input}, {scene},
// {output}, {log}, {mpmvv} (this executable), {threads} (mpmvv's thread
// count), {suites} (the shipped suites' folder, whose external/ holds the
// adapters to other codes); a value that is not a plain word is quoted for /bin/sh. {{ and }}
// are braces. A name that is neither is refused (ConfigError naming
// external_command and the name).
std::string expand_command(const std::string& templ, const Config& config, const ExternalFiles& files,
                           const std::string& executable, int threads);

// The input files: `files.scene`, a scene file holding every key of the
// resolved configuration, external_command cleared (what mpmvv run itself
// would run); `files.input`, JSON with the scene, every key, the output
// times, the end time, the tracers (each probe's material point X and its
// position at t = 0, in the order their positions are read back), the
// output's path and format. Throws ConfigError when a file cannot be written.
void write_external_input(const ExternalFiles& files, const Config& config, const std::vector<double>& output_times,
                          const std::vector<Vec2>& tracer_reference, const std::vector<Vec2>& tracer_start,
                          const std::string& format);

// How the program ended.
struct ProgramEnd {
  int exit_status = -1;     // its exit status when it exited
  int signal = 0;           // the signal that ended it, else 0
  bool timed_out = false;   // killed past the time-out
  bool stopped = false;     // killed because mpmvv was asked to stop (SIGINT, SIGTERM)
  double seconds = 0.0;     // wall time
  double ended_at = 0.0;    // when it was told to end (SIGTERM), if it was
  bool killed = false;      // it outlived SIGTERM by 5 s and was killed (SIGKILL)
  std::string log_tail;     // the last lines it printed
  bool succeeded() const { return exit_status == 0 && signal == 0 && !timed_out && !stopped; }
  std::string describe() const;  // "exit status 3", "killed after 60 s (external_timeout)", ...
};

// Runs `command` through /bin/sh, its output into `log_path`, in a process
// group of its own, which is ended (SIGTERM, then SIGKILL after 5 s) past
// `timeout` seconds (0: never) or when mpmvv's stop is requested
// (solver/time_loop.hpp: stop_request). `tick` is told the seconds so far,
// about every second. Throws std::runtime_error when it cannot be started.
ProgramEnd run_program(const std::string& command, const std::string& log_path, double timeout,
                       const std::function<void(double seconds)>& tick);

}  // namespace mpmvv::app
