// The checks make_stepper makes before it builds an explicit stepper.
#pragma once

#include "../boundary.hpp"
#include "../model.hpp"

namespace mpmvv {

// Throws std::invalid_argument naming the first option that does not go with
// the others, or what the particles or the scene's stages lack for them.
void check_explicit_options(const Model& model, const SolverOptions& options, const SceneStages& stages);

}  // namespace mpmvv
