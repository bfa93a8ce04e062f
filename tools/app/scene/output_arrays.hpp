// One output time's particles read from a file's arrays, whatever the
// file's format (particle_output.hpp): the readers of HDF5, CSV and VTK give
// their arrays under mpmvv's names, and this fills and checks the state.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "number_spacing.hpp"
#include "particle_output.hpp"

namespace mpmvv::app {

// One output's arrays as mpmvv names them (reference_position, position,
// reference_volume, velocity, stress, deformation_gradient, J, volume, mass),
// whatever the file's format: `get` gives an array as rows of `width` values
// (a tensor's four in-plane entries row-major) or none when the file does not
// hold it; `spelled` says how the file spells it, for messages.
struct ArraySource {
  struct Rows {
    std::vector<double> values;
    std::size_t rows = 0;
    double spacing = kDoubleSpacing;  // of the numbers as the file stores them
    bool text = false;                // counted from text's digits (number_spacing.hpp)
  };
  std::function<std::optional<Rows>(const std::string& name, std::size_t width)> get;
  std::function<std::string(const std::string& name)> spelled;
};

// The particles of one output from its arrays: the required three, then each
// optional field the file holds (OutputFields), with the rows checked.
void fill_state(OutputState& s, const ArraySource& source, const std::string& where);

// J from the volumes when no J was given; every reference volume positive.
void finish_state(OutputState& s, const std::string& where);

// The requested time k, or the program's own when close to it: within a
// hundredth of the gap to the requested time before (a code that steps with
// a fixed dt lands near, not on, an output time).
double checked_time(double own, const std::vector<double>& requested, std::size_t k, const std::string& where);

// `given` tracers where the input file lists `tracers`.
void check_tracers(std::size_t given, std::size_t tracers, const std::string& where);

// Whether the program wrote the file `path`: false when nothing is there;
// throws ParticleOutputError when what is there is not a regular file (a
// FIFO would block the reader, a directory or device is no output) or
// cannot be looked at (a symlink loop, a folder without permission).
bool output_file_written(const std::string& path);

}  // namespace mpmvv::app
