#include "stepper.hpp"

#include "io/state_archive.hpp"

namespace mpmvv {

void Stepper::persist(StateArchive& a) {
  a.field("particles", model_.particles);
  a.field("tracers", model_.tracers);
  a.field("ledger", ledger_);
  a.field("forcing_seconds", forcing_seconds_);
  a.field("stage_seconds", stage_times_);
  a.field("constraint_reactions", reactions_);
  a.field("contact_node_force", contact_forces_.node_force);
  a.field("contact_total", contact_forces_.total);
}

}  // namespace mpmvv
