// What an external program writes back (reports/external-format.md): its
// particles at each output time, as an HDF5 file of /snapshots/<k> groups
// (the layout of mpmvv's own results file with particle_fields = "outputs")
// or a folder of CSV or VTK files, read into the solver's particle arrays so
// that the norms are computed by the same code as for mpmvv's own runs. The
// HDF5 and CSV readers are in particle_output.cpp, the VTK one in
// particle_output_vtk.cpp; what they share, the state filled and checked from
// a file's arrays, in output_arrays.hpp.
#pragma once

#include <array>
#include <cstddef>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "solver/particles.hpp"

namespace mpmvv::app {

// Output that is missing or malformed: the message names the file, the
// group or line, and the item.
struct ParticleOutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Which of the optional fields an output held.
struct OutputFields {
  bool velocity = false, stress = false, deformation_gradient = false, J = false, volume = false, mass = false;
  bool tracers = false;
  bool operator==(const OutputFields&) const = default;
};

// One output time's particles: P holds reference_position, position and
// reference_volume, and each field `fields` says was given; the rest are NaN.
struct OutputState {
  double time = 0.0;  // the program's own time when it wrote one, else the requested time
  Particles P;
  std::vector<double> J;        // det F, from `J`, or volume / reference_volume (empty when neither)
  std::vector<Vec2> tracers;    // the tracers' current positions, in the input's order (empty when not given)
  OutputFields fields;
  // The coarsest relative spacing of the numbers the norms are differences
  // of, as written (number_spacing.hpp): positions, F, J, stress, velocity;
  // 2.2e-16 for doubles, 1.2e-7 for floats, 10^(1-d) for text of d digits.
  double output_spacing = 0.0;
};

// How a program's files spell mpmvv's items (external_names): mpmvv's name
// (a dataset or point array of the HDF5 and VTK layouts, a column of the CSV
// one) to the file's.
using OutputNames = std::map<std::string, std::string>;

// "reference_volume=vol0, velocity=velocities" for `format` (hdf5, csv,
// vtk); throws std::invalid_argument saying what is wrong (a pair without
// '=', a name the format does not have, listing those it has, a name or a
// file's name given twice).
OutputNames parse_output_names(const std::string& text, const std::string& format);

// Where a symmetric stress's 6 components stand in a program's VTK arrays
// (external_stress_order): order[i] is the place of component i of VTK's
// order xx, yy, zz, xy, yz, xz.
using StressOrder = std::array<std::size_t, 6>;
inline constexpr StressOrder kVtkStressOrder = {0, 1, 2, 3, 4, 5};

// "xx, yy, zz, yz, xz, xy" (Voigt's order), each of the six components once,
// yx, zy and zx standing for xy, yz and xz; throws std::invalid_argument
// naming a component that is unknown, repeated or missing.
StressOrder parse_stress_order(const std::string& text);

class ParticleOutput {
 public:
  // `path` and `format` as the input file named them; `requested` the output
  // times; `names` how the files spell the items they are not named as;
  // `stress_order` the order of a 6-component VTK stress.
  ParticleOutput(std::string path, std::string format, std::vector<double> requested, OutputNames names = {},
                 StressOrder stress_order = kVtkStressOrder);
  // The output for requested time k, or none when the program wrote none
  // for it; throws ParticleOutputError when what it wrote is malformed
  // (a missing required item, a row count or a column that does not match,
  // a time far from the requested one, a tracer count other than `tracers`).
  std::optional<OutputState> read(std::size_t k, std::size_t tracers) const;

 private:
  std::optional<OutputState> read_hdf5(std::size_t k, std::size_t tracers) const;
  std::optional<OutputState> read_csv(std::size_t k, std::size_t tracers) const;
  std::optional<OutputState> read_vtk(std::size_t k, std::size_t tracers) const;
  // The file's name of mpmvv's item `own`.
  std::string named(const std::string& own) const;
  std::string path_, format_;
  std::vector<double> requested_;
  OutputNames names_;
  StressOrder stress_order_;
};

}  // namespace mpmvv::app
