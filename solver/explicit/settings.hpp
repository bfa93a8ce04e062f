// What make_stepper chose for the explicit step beside its shape and material,
// each from SolverOptions (model.hpp), as the stepper holds it.
#pragma once

#include <cmath>
#include <numbers>

#include "../model.hpp"

namespace mpmvv {

struct StepSettings {
  Scheme scheme;
  bool apic;            // velocity_transfer = apic
  SolverFault fault;    // none, but in a fault-injection test (faults.hpp)
  Dilatation dilatation;
  double split_length;  // CPDI domains longer than this are split in two (split.hpp); 0: never
  double open_cos;      // CPDI domains whose sides meet at |cos| above this are turned (domain_angle.hpp); 1: never
  double viscosity_linear, viscosity_quadratic;  // bulk viscosity C0, C1 (add_bulk_viscosity); 0: none
};

// The cosine above which open_sheared_domains acts, from the angle in degrees below
// which a domain is turned; 1 (never) for 0.
inline double min_domain_angle_cosine(double degrees) {
  return degrees > 0.0 ? std::cos(degrees * std::numbers::pi / 180.0) : 1.0;
}

inline StepSettings step_settings(const SolverOptions& o, double h) {
  return {o.scheme,
          o.velocity_transfer == VelocityTransfer::apic,
          o.fault,
          o.dilatation,
          o.split_domains_beyond * h,
          min_domain_angle_cosine(o.min_domain_angle),
          o.bulk_viscosity_linear,
          o.bulk_viscosity_quadratic};
}

}  // namespace mpmvv
