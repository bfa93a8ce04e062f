// What a suite's cases will take before they run (`mpmvv suite --list`,
// `--budget`). Each case says its particles and steps (SceneCase::estimate:
// the steps from the step at rest, cfl h / c0). What that leaves out, the
// waves that speed up as the body deforms (the stiff vortex takes four times
// the steps at rest) and the rate of the scene's step, is measured on a
// calibration run of each study and method:
//   - an earlier run of the study and method in the suite's directory (the
//     case's own results file when it already ran: its own wall time), or
//   - its cheapest case run now, stopped after kProbeSeconds of wall time
//     (a run stopped early is extrapolated from the share of its end time it
//     reached, which the basis column says).
// A case then takes its own particles x steps at rest x the calibration's
// wall time per particle-step at rest (which holds its steps' growth, its
// particles' growth where domains split, and its rate); an implicit case (load steps, each a Newton solve) the
// calibration's wall time per load step x (particles over the calibration's)
// to the power 1.5.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "manifest.hpp"
#include "solver/time_loop.hpp"
#include "suite.hpp"

namespace mpmvv::app {

struct CaseEstimate {
  std::optional<double> seconds;  // none: not estimated (basis says why)
  std::optional<std::size_t> particles;
  std::optional<long long> steps;  // the steps it is expected to take (load steps where implicit)
  std::string basis;               // where the number comes from
};

// The selected cases of a suite in the runner's order, each with its
// estimate and when it would start and end on `jobs` slots (each case to the
// first free slot, as the runner takes them). A case not estimated takes no
// time in the schedule. Calibration runs print a line each on `err`.
struct PlannedCase {
  const SuiteCase* c = nullptr;
  CaseEstimate estimate;
  double start = 0.0, end = 0.0;  // seconds from the suite's start
};
std::vector<PlannedCase> plan_cases(const Suite& suite, const std::function<bool(const SuiteCase&)>& selected,
                                    const suite_file::SuiteDirectory& dir, int jobs, int threads, std::ostream& err);

// Wall time a calibration run of a study may take before it is stopped.
inline constexpr double kProbeSeconds = 5.0;

// The ring scene from t = 0 with `settings` (KEY=VALUE, over centre seeding
// and output only at the end), on the threads set now: the run whose rate is
// the throughput benchmark's (tools/bench/throughput.cpp).
RunOutcome ring_rate_run(const std::vector<std::string>& settings, std::size_t* particles = nullptr);

}  // namespace mpmvv::app
