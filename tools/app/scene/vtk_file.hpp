// The points of a VTK file and the arrays on them, as MPM codes write their
// particles: XML files (.vtu unstructured grid, .vtp poly data; ascii, inline
// binary or appended data, raw or base64, uncompressed or zlib-compressed)
// and legacy files (.vtk, ASCII or BINARY). The layouts are those of VTK's
// "VTK File Formats" document; cells are read past, not kept: a particle is
// a point. reports/external-format.md says what an external program writes.
#pragma once

#include <cstddef>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "number_spacing.hpp"

namespace mpmvv::app {

// A file that cannot be read as VTK: the message names the file and the item.
struct VtkFileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// An array of tuples, row-major: values.size() == tuples * components.
struct VtkArray {
  std::size_t components = 1;
  std::vector<double> values;
  double spacing = kDoubleSpacing;  // relative, of the numbers as stored (number_spacing.hpp)
  bool text = false;  // spacing counted from digits written as text: the writer's precision is at least that
  std::size_t tuples() const { return components == 0 ? 0 : values.size() / components; }
};

struct VtkPoints {
  VtkArray points;                           // N x 3
  std::map<std::string, VtkArray> point_data;  // by name, N tuples each
  std::map<std::string, VtkArray> field_data;  // the file's field data (a time, say)
};

// Reads .vtu, .vtp (XML) or .vtk (legacy) by the file's extension.
VtkPoints read_vtk_points(const std::string& path);

}  // namespace mpmvv::app
