// VTK's legacy files (.vtk, ASCII or BINARY): POINTS and the point data
// sections, cells and cell data read past.
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <map>
#include <string>

#include <fmt/format.h>

#include "vtk_values.hpp"

namespace mpmvv::app::vtk {

namespace {

class LegacyReader {
 public:
  LegacyReader(std::string path) : path_(std::move(path)), text_(file_bytes(path_)) {}

  VtkPoints read() {
    if (line().rfind("# vtk DataFile Version", 0) != 0)
      throw VtkFileError(fmt::format("{}: the first line is not '# vtk DataFile Version ...'", path_));
    line();  // the title
    const std::string mode = upper(trim(line()));
    if (mode != "ASCII" && mode != "BINARY") throw VtkFileError(fmt::format("{}: line 3 is '{}', not ASCII or BINARY", path_, mode));
    binary_ = mode == "BINARY";
    VtkPoints out;
    std::map<std::string, VtkArray>* data = &out.field_data;  // FIELD before any POINT_DATA is the file's
    std::size_t expected = 0;                                  // tuples of the current POINT_DATA or CELL_DATA
    bool cells = false;
    for (std::string key = token(); !key.empty(); key = token()) {
      key = upper(key);
      if (key == "DATASET") {
        const std::string type = upper(token());
        if (type != "POLYDATA" && type != "UNSTRUCTURED_GRID" && type != "STRUCTURED_GRID")
          throw VtkFileError(fmt::format("{}: DATASET {}: particles are read from POLYDATA or UNSTRUCTURED_GRID", path_, type));
      } else if (key == "POINTS") {
        const std::size_t n = count("POINTS");
        if (n > text_.size()) throw VtkFileError(fmt::format("{}: POINTS {} in a file of {} bytes", path_, n, text_.size()));
        out.points = values(3 * n, type_of(token()), 3);
      } else if (key == "VERTICES" || key == "LINES" || key == "POLYGONS" || key == "TRIANGLE_STRIPS" || key == "CELLS") {
        const std::size_t n = count(key), size = count(key);
        skip_connectivity(n, size);
      } else if (key == "CELL_TYPES") {
        values(count(key), ValueType{ValueType::signed_integer, 4});
      } else if (key == "POINT_DATA" || key == "CELL_DATA") {
        expected = count(key);
        cells = key == "CELL_DATA";
        data = cells ? &dropped_ : &out.point_data;
        if (!cells && expected != out.points.tuples())
          throw VtkFileError(fmt::format("{}: POINT_DATA {} for {} points", path_, expected, out.points.tuples()));
      } else if (key == "SCALARS") {
        const std::string name = token();
        const ValueType t = type_of(token());
        std::string next = token();
        std::size_t components = 1;
        if (upper(next) != "LOOKUP_TABLE") {
          components = number(next, "SCALARS");
          next = token();
        }
        if (upper(next) != "LOOKUP_TABLE") throw VtkFileError(fmt::format("{}: SCALARS {}: no LOOKUP_TABLE line", path_, name));
        token();  // the table's name
        (*data)[name] = values(expected * components, t, components);
      } else if (key == "VECTORS" || key == "NORMALS" || key == "TENSORS" || key == "TENSORS6") {
        const std::string name = token();
        const std::size_t components = key == "TENSORS" ? 9 : key == "TENSORS6" ? 6 : 3;
        (*data)[name] = values(expected * components, type_of(token()), components);
      } else if (key == "FIELD") {
        token();  // its name
        const std::size_t arrays = count("FIELD");
        for (std::size_t i = 0; i < arrays; ++i) {
          const std::string name = token();
          const std::size_t components = count(name), tuples = count(name);
          const ValueType t = type_of(token());
          if (data == &out.point_data && tuples != expected)
            throw VtkFileError(fmt::format("{}: FIELD array '{}' has {} tuples for {} points", path_, name, tuples, expected));
          (*data)[name] = values(components * tuples, t, components);
        }
      } else if (key == "METADATA") {
        while (pos_ < text_.size() && !trim(line()).empty()) {}
      } else {
        throw VtkFileError(fmt::format("{}: section '{}' is not read (POINTS, cells, POINT_DATA, CELL_DATA, SCALARS, "
                                       "VECTORS, NORMALS, TENSORS, FIELD, METADATA are)", path_, key));
      }
    }
    if (out.points.values.empty() && out.points.components == 1)
      throw VtkFileError(fmt::format("{}: no POINTS", path_));
    return out;
  }

 private:
  static std::string upper(std::string s) {
    for (char& c : s) c = char(std::toupper(static_cast<unsigned char>(c)));
    return s;
  }
  static std::string trim(const std::string& s) {
    const std::size_t a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
    return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
  }
  std::string line() {
    const std::size_t end = std::min(text_.find('\n', pos_), text_.size());
    std::string s = text_.substr(pos_, end - pos_);
    pos_ = std::min(end + 1, text_.size());
    return s;
  }
  std::string token() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    return text_.substr(start, pos_ - start);
  }
  std::size_t number(const std::string& s, const std::string& what) {
    char* end = nullptr;
    const long long v = std::strtoll(s.c_str(), &end, 10);
    if (s.empty() || *end != '\0' || v < 0) throw VtkFileError(fmt::format("{}: {}: '{}' is not a count", path_, what, s));
    return std::size_t(v);
  }
  std::size_t count(const std::string& what) { return number(token(), what); }
  ValueType type_of(const std::string& name) {
    static const std::map<std::string, ValueType> types = {
        {"float", {ValueType::floating, 4}},          {"double", {ValueType::floating, 8}},
        {"char", {ValueType::signed_integer, 1}},     {"unsigned_char", {ValueType::unsigned_integer, 1}},
        {"short", {ValueType::signed_integer, 2}},    {"unsigned_short", {ValueType::unsigned_integer, 2}},
        {"int", {ValueType::signed_integer, 4}},      {"unsigned_int", {ValueType::unsigned_integer, 4}},
        {"long", {ValueType::signed_integer, 8}},     {"unsigned_long", {ValueType::unsigned_integer, 8}},
        {"vtktypeint64", {ValueType::signed_integer, 8}}, {"vtktypeuint64", {ValueType::unsigned_integer, 8}},
        {"vtkidtype", {ValueType::signed_integer, 8}}};
    std::string lower = name;
    for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
    const auto it = types.find(lower);
    if (it == types.end()) throw VtkFileError(fmt::format("{}: data type '{}' is not read", path_, name));
    return it->second;
  }
  // n values of type t: text numbers, or big-endian bytes from the line
  // after the header; as `components`-tuples, with their spacing.
  VtkArray values(std::size_t n, ValueType t, std::size_t components = 1) {
    VtkArray a;
    // A count read from the file bounds nothing: n values must fit in the
    // bytes left (a text number and its separator take two at least) before
    // anything is allocated.
    const std::size_t left = text_.size() - pos_;
    if (binary_ ? n > left / t.size : n > left / 2 + 1)
      throw VtkFileError(fmt::format("{}: {} values declared where {} bytes are left", path_, n, left));
    if (!binary_) {
      a.values.resize(n);
      int digits = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const std::string s = token();
        char* end = nullptr;
        a.values[i] = std::strtod(s.c_str(), &end);
        if (s.empty() || *end != '\0')
          throw VtkFileError(fmt::format("{}: value {} of {}: '{}' is not a number", path_, i, n, s));
        digits = std::max(digits, significant_digits(s));
      }
      a.spacing = digits_spacing(digits);
      a.text = true;
    } else {
      line();  // the rest of the header line
      if (n > (text_.size() - pos_) / t.size)
        throw VtkFileError(fmt::format("{}: the binary data end before {} values", path_, n));
      a = binary_array(text_.substr(pos_, n * t.size), t, true);
      pos_ += n * t.size;
    }
    a.components = components;
    return a;
  }
  // Cells: the old layout (size integers) or version 5's OFFSETS and CONNECTIVITY.
  void skip_connectivity(std::size_t n, std::size_t size) {
    const std::size_t mark = pos_;
    if (upper(token()) == "OFFSETS") {
      values(n, type_of(token()));
      if (upper(token()) != "CONNECTIVITY") throw VtkFileError(fmt::format("{}: OFFSETS without CONNECTIVITY", path_));
      values(size, type_of(token()));
      return;
    }
    pos_ = mark;
    values(size, ValueType{ValueType::signed_integer, 4});
  }

  std::string path_, text_;
  std::size_t pos_ = 0;
  bool binary_ = false;
  std::map<std::string, VtkArray> dropped_;  // cell data: read past
};

}  // namespace

VtkPoints read_legacy(const std::string& path) { return LegacyReader(path).read(); }

}  // namespace mpmvv::app::vtk
