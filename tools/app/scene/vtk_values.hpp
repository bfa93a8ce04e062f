// The pieces the XML and the legacy VTK readers share (vtk_file.cpp): a
// file's bytes, a number type, values from binary or text numbers with their
// spacing; and the two readers, which read_vtk_points chooses between.
#pragma once

#include <cstddef>
#include <string>

#include "vtk_file.hpp"

namespace mpmvv::app::vtk {

// A scalar type of the file, by its size and kind.
struct ValueType {
  enum Kind { floating, signed_integer, unsigned_integer } kind = floating;
  std::size_t size = 8;
};

std::string file_bytes(const std::string& path);

// The bytes of one value, in the file's byte order, as a double.
double value_of(const char* bytes, ValueType t, bool big_endian);

// An array's values from binary numbers of type t, their spacing with them.
VtkArray binary_array(const std::string& bytes, ValueType t, bool big_endian);

// Whitespace-separated numbers; their spacing from the most digits any has.
VtkArray ascii_values(const char* text, const std::string& where);

VtkPoints read_xml(const std::string& path);     // vtk_xml.cpp
VtkPoints read_legacy(const std::string& path);  // vtk_legacy.cpp

}  // namespace mpmvv::app::vtk
