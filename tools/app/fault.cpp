#include "fault.hpp"

#include <cstdlib>

#include <fmt/format.h>

#include "config.hpp"

namespace mpmvv::app {

namespace {

const char* kind_name(Fault::Kind k) {
  switch (k) {
    case Fault::none: return "";
    case Fault::no_body_force: return "no-body-force";
    case Fault::exact_seeding_volume: return "exact-seeding-volume";
    case Fault::crash: return "crash";
    case Fault::hang: return "hang";
    case Fault::solver: return "solver";
  }
  return "?";
}

}  // namespace

std::string to_string(const Fault& f) {
  return f.kind == Fault::solver ? mpmvv::to_string(f.in_solver) : kind_name(f.kind);
}

Fault injected_fault(const std::string& results_path) {
  const char* value = std::getenv("MPMVV_FAULT");
  if (!value || !*value) return {};
  Fault f;
  for (Fault::Kind k : {Fault::no_body_force, Fault::exact_seeding_volume, Fault::crash, Fault::hang})
    if (std::string(value) == kind_name(k)) f.kind = k;
  if (f.kind == Fault::none) {
    f.in_solver = solver_fault_named(value);
    if (f.in_solver == SolverFault::none) {
      std::string names = "no-body-force, exact-seeding-volume, crash, hang";
      for (SolverFault s : kSolverFaults) names += fmt::format(", {}", mpmvv::to_string(s));
      throw ConfigError(fmt::format("MPMVV_FAULT={}: unknown fault ({})", value, names));
    }
    f.kind = Fault::solver;
  }
  const char* only = std::getenv("MPMVV_FAULT_ONLY");
  if (only && *only && results_path.find(only) == std::string::npos) return {};
  return f;
}

}  // namespace mpmvv::app
