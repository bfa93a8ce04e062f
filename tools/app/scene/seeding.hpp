// Seeding: a scene's body filled with particles, each in the exact state at
// t = 0, and the memory a run of it will hold, known before anything is
// allocated.
#pragma once

#include <cstddef>

#include "solver/model.hpp"
#include "tools/app/config.hpp"
#include "tools/app/scene/setup.hpp"

namespace mpmvv::app {

struct SeedingPlan {
  int particles_per_direction;
  bool exact;       // seeding = "exact": clipped pieces of the CGAL body; else sub-cell centres in the body
  bool half_sizes;  // a method with particle domains (all but linear): each particle's half-size
  bool outlines;    // exact CPDI with exact seeding: each clipped piece's outline as its domain
  // A deliberate fault (tools/app/fault.hpp: exact-seeding-volume): a piece
  // the boundary cuts keeps the whole sub-cell's area (and its r-moment in
  // r-z) as its volume, not the part inside the body.
  bool whole_cut_volume = false;
};

struct Seeded {
  double particle_volume = 0.0;         // the particles' total reference volume (per radian in r-z)
  std::size_t first_material_count = 0;  // with a second material: the particles of the first
};

// Particles on a regular sub-lattice of every cell, in cell order, so that
// neighbours in memory are neighbours in space. With exact seeding a sub-cell
// the boundary cuts holds the part of the body inside it: its exact area and
// centroid; slivers under a tenth of a sub-cell join the largest piece of
// their cell, and a clipped particle's domain shrinks to its area. With
// centre seeding a particle sits wherever its sub-cell centre lies in the
// body. Each starts in the exact state at t = 0, from the same definition as
// the force. In r-z a particle's volume is per radian: the integral of r over
// its area.
Seeded seed_particles(const SceneSetup& setup, const SeedingPlan& plan, Particles& P);

// The body's exact volume (per radian in r-z), from its CGAL description; NaN
// without one.
double exact_body_volume(const SceneSetup& setup);

// The memory the case will hold, estimated before anything is allocated: the
// particles (at most about 400 bytes each with the stencils a step stores and
// the copies an output makes; 168-280 measured for CPDI,
// mpmvv-bench-throughput) and the grid (the fields of GridFields, 11 doubles
// per node, and a scatter buffer of 5 doubles per node for each thread). A
// case that cannot fit in the machine's memory is refused (ConfigError),
// naming the keys that set it, rather than ending in an allocation failure.
void refuse_what_cannot_fit(const SceneSetup& setup, const Config& config);

}  // namespace mpmvv::app
