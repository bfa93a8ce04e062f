// A case whose run is another MPM code's (external_command): the harness
// writes the case's input, runs the program, reads its particles at every
// output time (particle_output.hpp) and measures them against the scene's
// exact solution with the norms, probe lines and health rules of its own
// runs (norms.hpp, probes.hpp, health.hpp).
#pragma once

#include <memory>

#include "external_program.hpp"
#include "scene.hpp"

namespace mpmvv::app {

// Throws ConfigError (naming external_command) for a scene whose errors only
// mpmvv's own solver can measure: no exact motion, errors of its own, a
// static settling, r-z.
std::unique_ptr<SceneCase> make_external_case(const Config& config, const SceneType& type,
                                              const ExternalProgram& program);

}  // namespace mpmvv::app
