// Deliberate faults, for showing that the gate catches real defects and that a
// suite survives a broken case. Set MPMVV_FAULT for `mpmvv run` (a suite passes
// its environment to every case):
//   no-body-force   the scene's body force stage is left out
//   cpdi-gradient   CPDI corner gradients carry 1/4 * 1.04 instead of 1/4 (eq. 1.100)
//   crash           the run aborts after reading its configuration
//   hang            the run never ends
// With MPMVV_FAULT_ONLY=TEXT the fault applies only to runs whose results file
// path contains TEXT (one case of a suite). A results file records the fault it
// ran with (attribute fault_injected).
#pragma once

#include <string>

namespace mpmvv::app {

enum class Fault { none, no_body_force, cpdi_gradient, crash, hang };

// From MPMVV_FAULT (and MPMVV_FAULT_ONLY) for a run writing `results_path`;
// throws ConfigError for a value not listed above.
Fault injected_fault(const std::string& results_path);
const char* to_string(Fault f);

// The factor a cpdi-gradient fault puts on CPDI gradients.
inline constexpr double kFaultyCpdiGradientScale = 1.04;

}  // namespace mpmvv::app
