// Suites (suites/README.md): a file of studies (a scene, its sweeps and
// overrides) and expectations; the runner that runs every case in a process of
// its own; the manifest that records what happened to each.
#pragma once

#include <iosfwd>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "tools/app/json.hpp"

namespace mpmvv::app {

// One run of a scene: the key=value overrides that make it, in order.
struct SuiteCase {
  std::string id;                      // "<study>-<key>=<value>-..."
  std::string study;
  std::string scene_file;              // as the runner passes it to `mpmvv run`
  std::vector<std::string> overrides;  // "key=value"
  std::string configuration;           // the resolved configuration (TOML), to recognise a finished case
  std::string defaults;                // the scene's defaults in the same form, for results older than a key
  std::map<std::string, Json> keys;  // every resolved scene key: a number, a string or a list of numbers
  std::vector<std::string> error_columns;  // the /errors columns its run can write (SceneCase::possible_error_columns)
};

// A suite's tiers (suites/README.md): the full study, and the cheap one every
// merge runs (each study's `ci` table says its cases there; each expectation's
// `tier` whether it applies there).
inline constexpr const char* kFullTier = "full";
inline constexpr const char* kCiTier = "ci";
// The most cases a suite may make (the largest shipped suite makes a few hundred).
inline constexpr std::size_t kMaxCases = 10000;

struct Suite {
  std::string name;         // file stem
  std::string file;
  // The file's text as parsed: written as DIR/suite.toml and recorded in the
  // manifest ("suite_text"), so the gate can tell the suite.toml beside it
  // is the one that ran (reports/consistency.py).
  std::string text;
  std::string description;
  std::string tier = kFullTier;  // the tier loaded: its cases and its expectations only
  // The suite's [ci] table: what its ci tier covers that the others do not,
  // or, for a suite without one, why (`skip`: it needs a program built
  // elsewhere). Empty where the file says nothing.
  std::string ci_covers;
  std::string ci_skip;
  double timeout_seconds = 3600.0;
  // Wall time between the saves of each case's state (mpmvv run
  // --checkpoint-every), so that a case longer than a sitting goes on where it
  // stopped when the suite is run again; 0: no saves, an unfinished case runs
  // again from t = 0.
  double checkpoint_seconds = 0.0;
  std::vector<SuiteCase> cases;
  // The [[expect]] tables, each checked against the studies and their cases,
  // as JSON (the manifest's "expectations": the gate's and the report's).
  std::vector<Json> expectations;
  // What the loader found doubtful but not wrong, each with the file and line
  // (an expectation read where the exact signal is trivial).
  std::vector<std::string> warnings;
};

// Reads and checks a suite file and every case it makes; throws ConfigError
// with the file, line and key of the first mistake. Nothing runs. `tier`:
// kFullTier or kCiTier (a suite that has no ci tier is refused for it, naming
// why when its [ci] table's `skip` says so: SuiteSkipped).
Suite load_suite(const std::string& path, const std::string& tier = kFullTier);

// The ci tier asked of a suite that declares it has none ([ci] skip = "...").
struct SuiteSkipped : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The environment variable through which a suite tells each case it starts
// its process id: the case asks the kernel for SIGTERM when that process ends
// (a suite killed by SIGKILL leaves no case running).
inline constexpr const char* kSuiteParent = "MPMVV_SUITE_PARENT";

struct SuiteRequest {
  std::string suite_file;
  std::string output_dir;    // default: results/<suite name>
  int jobs = 1;              // cases at once (per MPI rank)
  int threads = 0;           // OpenMP threads per case; 0: the cores shared out over jobs and ranks
  bool quiet = false;
  bool list = false;         // check the suite and print its cases; run nothing
  std::string only;          // a regular expression: run (or list) only the cases whose id it finds; "" all
  std::string tier = kFullTier;
  double budget_seconds = 0.0;  // > 0: say which cases a run of that wall time will not reach (estimate.hpp)
  bool force = false;        // run in a directory that holds another suite's results (its manifest is replaced)
};

// Whether a results file written with configuration `stored` is the run that
// `wanted` asks for now. Every key stored must have the value wanted. A key
// wanted but absent from `stored` was added to the scene after that file was
// written; keys are added with defaults that keep the earlier behaviour, so
// such a key must be at its default (`defaults`, the scene's configuration with
// nothing set) for the file to count. Those keys are listed in `added`.
bool same_configuration(const std::string& stored, const std::string& wanted, const std::string& defaults,
                        std::vector<std::string>* added = nullptr);

// Exit status: 0 every case (every case --only selects) completed or was
// stopped by the solver (both are results); 1 a case crashed, timed out or was
// refused; 2 bad input; 130
// interrupted (rerun to resume).
int run_suite(const SuiteRequest& request, std::ostream& out, std::ostream& err);

}  // namespace mpmvv::app
