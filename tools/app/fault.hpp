// Deliberate faults, for showing that the gate catches real defects and that a
// suite survives a broken case. Set MPMVV_FAULT for `mpmvv run` (a suite passes
// its environment to every case) to one of
//   no-body-force         the scene's body force stage is left out
//   exact-seeding-volume  exact seeding gives a particle the boundary cuts
//                         its whole sub-cell's volume, not its cut area
//   crash                 the run aborts after reading its configuration
//   hang                  the run never ends
// or to a mistake in the explicit step, solver/faults.hpp (cpdi-weight,
// cpdi-gradient, cpdi-shear-sign, linear-gradient, gimp-gradient,
// deformation-transpose, frozen-volume, lagged-stress, no-hoop-stress,
// force-at-current-position, lagged-force-time, frozen-time-step,
// consistent-mass, pic-velocity, kirchhoff-stress, wrong-shear-modulus,
// non-objective-stress, swapped-walls, mirrored-wall, apic-transpose,
// traction-factor). With MPMVV_FAULT_ONLY=TEXT the fault applies only to runs
// whose results file path contains TEXT (one case of a suite). A results file
// records the fault it ran with (attribute fault_injected).
#pragma once

#include <string>

#include "solver/faults.hpp"

namespace mpmvv::app {

struct Fault {
  enum Kind { none, no_body_force, exact_seeding_volume, crash, hang, solver };
  Kind kind = none;
  SolverFault in_solver = SolverFault::none;  // kind == solver: which

  bool operator==(Kind k) const { return kind == k; }
};

// From MPMVV_FAULT (and MPMVV_FAULT_ONLY) for a run writing `results_path`;
// throws ConfigError for a value not listed above.
Fault injected_fault(const std::string& results_path);
// Its name as MPMVV_FAULT spells it; empty for none.
std::string to_string(const Fault& f);

}  // namespace mpmvv::app
