// A restart file (mpmvv run --checkpoint-every, --pause-at, --resume): the
// run's state between two steps, the time loop's, the stepper's and what the
// scene has recorded so far, each in a group of its own (solver/io/
// state_archive.hpp), with the attributes that say which run it belongs to.
#pragma once

#include <functional>
#include <string>

#include "solver/io/state_archive.hpp"
#include "solver/stepper.hpp"
#include "solver/time_loop.hpp"
#include "tools/app/scene/scene.hpp"

namespace mpmvv::app {

// `scene` writes (or reads) the scene's own record into the archive it is given.
using ScenePersist = std::function<void(StateArchive&)>;

// Written to a partial file and renamed, so that a run killed while it saves
// keeps the state it saved before; a save that fails is told (restart.tell)
// and the run goes on without it.
void save_restart(const RestartPlan& restart, const LoopState& state, Stepper& stepper, const ScenePersist& scene);

// Reads the state saved at `path` into `loop`, the stepper and the scene;
// throws ConfigError when it cannot.
void read_restart(const std::string& path, LoopState& loop, Stepper& stepper, const ScenePersist& scene);

}  // namespace mpmvv::app
