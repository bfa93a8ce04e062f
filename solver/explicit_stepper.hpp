// The explicit MPM step. A stepper is built once per run for one method,
// material and scheme; the scene's optional stages (body force, tracers) are
// present only when the scene gave them.
#pragma once

#include <memory>

#include "model.hpp"
#include "stepper.hpp"

namespace mpmvv {

// Particle outlines (Particles::domain_vertex), when there are any, belong to
// exact CPDI and hold 3 to CpdiExactShape::kMaxOutline points each; throws
// std::invalid_argument otherwise.
void check_domain_outlines(const Particles& P, Method method);

// Checks the particles carry what the method needs, then picks the stepper
// instantiation for (method, material): the one dispatch.
std::unique_ptr<Stepper> make_stepper(Model model, const SolverOptions& options,
                                      const MaterialModel& material, SceneStages stages);
// A scene whose only optional stage is a body force (or none).
std::unique_ptr<Stepper> make_stepper(Model model, const SolverOptions& options,
                                      const MaterialModel& material,
                                      std::shared_ptr<BodyForce> body_force);

}  // namespace mpmvv
