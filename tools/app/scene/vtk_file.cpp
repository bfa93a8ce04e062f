// Values of VTK files, shared by the XML and the legacy readers, and the
// choice between the two by the file's extension.
#include "vtk_file.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string_view>

#include <fmt/format.h>

#include "vtk_values.hpp"

namespace mpmvv::app {

namespace vtk {

namespace {

// A value of type T from its bytes in host order.
template <class T>
double load(const unsigned char* b) {
  T v;
  std::memcpy(&v, b, sizeof(T));
  return double(v);
}

std::vector<double> values_of(const std::string& bytes, ValueType t, bool big_endian) {
  std::vector<double> v(bytes.size() / t.size);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = value_of(bytes.data() + i * t.size, t, big_endian);
  return v;
}

}  // namespace

std::string file_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw VtkFileError(fmt::format("{}: cannot be read", path));
  return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

double value_of(const char* bytes, ValueType t, bool big_endian) {
  unsigned char b[8];
  std::memcpy(b, bytes, t.size);
  if (big_endian != (std::endian::native == std::endian::big)) std::reverse(b, b + t.size);
  const bool is_signed = t.kind == ValueType::signed_integer;
  if (t.kind == ValueType::floating) return t.size == 4 ? load<float>(b) : load<double>(b);
  switch (t.size) {
    case 1: return is_signed ? load<std::int8_t>(b) : load<std::uint8_t>(b);
    case 2: return is_signed ? load<std::int16_t>(b) : load<std::uint16_t>(b);
    case 4: return is_signed ? load<std::int32_t>(b) : load<std::uint32_t>(b);
    default: return is_signed ? load<std::int64_t>(b) : load<std::uint64_t>(b);
  }
}

VtkArray binary_array(const std::string& bytes, ValueType t, bool big_endian) {
  VtkArray a;
  a.values = values_of(bytes, t, big_endian);
  a.spacing = binary_spacing(t.kind == ValueType::floating, t.size, a.values);
  return a;
}

VtkArray ascii_values(const char* text, const std::string& where) {
  VtkArray a;
  int digits = 0;
  const char* p = text;
  for (;;) {
    while (*p && std::isspace(static_cast<unsigned char>(*p))) ++p;
    if (!*p) break;
    char* end = nullptr;
    const double x = std::strtod(p, &end);
    if (end == p) throw VtkFileError(fmt::format("{}: '{}' is not a number", where, std::string(p, std::min<std::size_t>(std::strlen(p), 20))));
    a.values.push_back(x);
    digits = std::max(digits, significant_digits(std::string_view(p, std::size_t(end - p))));
    p = end;
  }
  a.spacing = digits_spacing(digits);
  a.text = true;
  return a;
}

}  // namespace vtk

VtkPoints read_vtk_points(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".vtu" || ext == ".vtp") return vtk::read_xml(path);
  if (ext == ".vtk") return vtk::read_legacy(path);
  throw VtkFileError(fmt::format("{}: not a .vtu, .vtp or .vtk file", path));
}

}  // namespace mpmvv::app
