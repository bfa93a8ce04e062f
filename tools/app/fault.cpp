#include "fault.hpp"

#include <cstdlib>

#include <fmt/format.h>

#include "config.hpp"

namespace mpmvv::app {

const char* to_string(Fault f) {
  switch (f) {
    case Fault::none: return "";
    case Fault::no_body_force: return "no-body-force";
    case Fault::cpdi_gradient: return "cpdi-gradient";
    case Fault::crash: return "crash";
    case Fault::hang: return "hang";
  }
  return "?";
}

Fault injected_fault(const std::string& results_path) {
  const char* value = std::getenv("MPMVV_FAULT");
  if (!value || !*value) return Fault::none;
  const char* only = std::getenv("MPMVV_FAULT_ONLY");
  for (Fault f : {Fault::no_body_force, Fault::cpdi_gradient, Fault::crash, Fault::hang})
    if (std::string(value) == to_string(f))
      return only && *only && results_path.find(only) == std::string::npos ? Fault::none : f;
  throw ConfigError(fmt::format("MPMVV_FAULT={}: unknown fault (no-body-force, cpdi-gradient, crash, hang)", value));
}

}  // namespace mpmvv::app
