// One case end to end: read and check the scene file and overrides, run it,
// write the results file atomically, print the error table.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace mpmvv::app {

struct RunRequest {
  std::string scene_file;
  std::vector<std::string> overrides;  // "key=value"
  std::string output;                  // results file; empty: <scene file stem>.h5
  bool quiet = false;                  // no echo, no progress
  bool describe = false;               // print the resolved configuration and stop
  int threads = 0;                     // 0: the OpenMP default
  // A restart file, <output>.restart (restart_path): saved every this many
  // seconds of wall time and when the run stops early; 0: never.
  double checkpoint_every = 0.0;
  double pause_at = -1.0;  // when >= 0, stop from this simulated time on, saving the state
  // Go on from the restart file when there is one: `yes` refuses a file of
  // another run (configuration, build, threads), `if_same` starts such a run
  // from t = 0 instead (what a suite asks for, where a file an older build
  // left must not stop the case).
  enum class Resume { no, yes, if_same };
  Resume resume = Resume::no;
  std::string command_line;
};

// Where a run writing `output` keeps its state for --resume.
std::string restart_path(const std::string& output);

// Exit status: 0 the run completed; 1 the solver stopped it (results written,
// status "failed"); 2 bad input (nothing run).
int run_case(const RunRequest& request, std::ostream& out, std::ostream& err);

// The resolved configuration of a scene file with overrides, one key per line
// with its meaning and allowed range; throws ConfigError.
std::string describe_configuration(const std::string& scene_file, const std::vector<std::string>& overrides);

// Every scene and its keys.
std::string describe_scenes();

std::string version_string();

// Hands over to a module of the reports package (`python3 -m reports.MODULE`)
// under /usr/bin/python3, which sees Debian's numpy, h5py and matplotlib;
// returns only if it cannot start.
int run_report_tool(const std::string& module, const std::vector<std::string>& arguments, std::ostream& err);

}  // namespace mpmvv::app
