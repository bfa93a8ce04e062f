// A case's process: `mpmvv run` with the case's settings, in a process group
// of its own so that the suite can stop it whole, and the state it left when
// it ended.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string>

#include "manifest.hpp"
#include "tools/app/installation.hpp"
#include "suite.hpp"

namespace mpmvv::app::suite_file {

// Starts `mpmvv run` for case `c` writing `results`, its output in `log`:
// `threads` OpenMP threads, waiting passively where cases share the cores,
// saving its state every `checkpoint_seconds` (0: never).
pid_t spawn_case(const std::string& exe, const SuiteCase& c, const std::filesystem::path& results,
                 const std::filesystem::path& log, int threads, bool passive_wait, double checkpoint_seconds);

// The state of a case whose process ended with wait status `status` after
// `wall` seconds: what its results file records when it ran to an end
// (exit 0 or 1), else what the runner saw.
CaseState ended_state(const SuiteDirectory& dir, const SuiteCase& c, int status, bool timed_out, double wall,
                      double timeout_seconds);

}  // namespace mpmvv::app::suite_file
