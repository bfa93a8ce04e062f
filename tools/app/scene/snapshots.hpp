// The particles' fields at every output time, when a run asks for them
// (particle_fields = "outputs"): reference position and volume, position,
// displacement, velocity, J, the Cauchy stress, F and, with an exact motion,
// the displacement error; and the tracers' positions. The same layout is
// what an external program writes for mpmvv to read (particle_output.hpp),
// so a results file of mpmvv's own is such an output. The
// results file holds them under /snapshots, and its .xmf sidecar
// (xdmf_file.hpp) lets ParaView animate them. Each output keeps its own
// particle count (a split adds particles).
#pragma once

#include <cstddef>
#include <vector>

#include "mms/exact_solution.hpp"
#include "solver/io/hdf5.hpp"
#include "solver/io/state_archive.hpp"
#include "solver/particles.hpp"

namespace mpmvv::app {

class ParticleSnapshots {
 public:
  // `exact`: the exact motion, or null for a scene without one (no error field).
  void record(double t, const Particles& P, const mms::ExactSolution* exact, const std::vector<Vec2>& tracers);
  bool empty() const { return time_.empty(); }
  // The most particles any output held.
  std::size_t largest_count() const;
  // /snapshots/<k> for the k-th output: attribute `time`, and the fields.
  void write(h5::Group& root) const;
  void persist(StateArchive& a);

 private:
  std::vector<double> time_;
  std::vector<std::vector<double>> reference_position_, reference_volume_, position_, displacement_, velocity_, J_,
      stress_, F_, error_, tracer_position_;
};

}  // namespace mpmvv::app
