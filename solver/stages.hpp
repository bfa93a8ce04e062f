// The stages of an explicit MPM step as free functions over particle and grid
// arrays (002_c3305cb8b1bc1490.txt section 1.5). A stepper composes them in the
// order of its stress-update scheme. Every choice (shape function, material,
// which fields move) is a template parameter: it is made once per stage, never
// per particle.
//
// Threads: particles are split statically over threads. Particle-to-grid
// scatters into one private buffer per thread and the buffers are summed node
// by node in thread order, so a run is bit-for-bit repeatable for a given
// thread count.//
// Each stage is a header of solver/stages/, in the order of a step.
#pragma once

#include "stages/scatter.hpp"
#include "stages/particle_to_grid.hpp"
#include "stages/grid_update.hpp"
#include "stages/grid_to_particle.hpp"
#include "stages/dilatation.hpp"
#include "stages/stress_update.hpp"
#include "stages/tracers.hpp"
#include "stages/time_step_scan.hpp"
