#include "vtk_file.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string_view>

#include <fmt/format.h>
#include <pugixml.hpp>
#include <zlib.h>

namespace mpmvv::app {

namespace fs = std::filesystem;

namespace {

std::string file_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw VtkFileError(fmt::format("{}: cannot be read", path));
  return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

// A scalar type of the file, by its size and kind.
struct ValueType {
  enum Kind { floating, signed_integer, unsigned_integer } kind = floating;
  std::size_t size = 8;
};

// A value of type T from its bytes in host order.
template <class T>
double load(const unsigned char* b) {
  T v;
  std::memcpy(&v, b, sizeof(T));
  return double(v);
}

// The bytes of one value, in the file's byte order, as a double.
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

std::vector<double> values_of(const std::string& bytes, ValueType t, bool big_endian) {
  std::vector<double> v(bytes.size() / t.size);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = value_of(bytes.data() + i * t.size, t, big_endian);
  return v;
}

// An array's values from binary numbers of type t, their spacing with them.
VtkArray binary_array(const std::string& bytes, ValueType t, bool big_endian) {
  VtkArray a;
  a.values = values_of(bytes, t, big_endian);
  a.spacing = binary_spacing(t.kind == ValueType::floating, t.size, a.values);
  return a;
}

// Whitespace-separated numbers; their spacing from the most digits any has.
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

// ---------------------------------------------------------------- XML files

// The next bytes of a DataArray's data: raw (appended, encoding="raw") or
// base64. VTK encodes a binary array's header and its data as two base64
// runs, each padded on its own, where other writers encode them as one: the
// decoder takes each padded quantum as it comes, so both read the same.
class ByteStream {
 public:
  ByteStream(const std::string& text, std::size_t pos, bool base64, std::string where)
      : text_(text), pos_(pos), base64_(base64), where_(std::move(where)) {}

  std::string read(std::size_t n) {
    if (!base64_) {
      if (pos_ + n > text_.size()) throw VtkFileError(fmt::format("{}: the data end before {} more bytes", where_, n));
      std::string out = text_.substr(pos_, n);
      pos_ += n;
      return out;
    }
    while (pending_.size() < n) decode_quantum();
    std::string out = pending_.substr(0, n);
    pending_.erase(0, n);
    return out;
  }

 private:
  static int sextet(char c) {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  }
  void decode_quantum() {
    char q[4];
    for (int i = 0; i < 4; ++i) {
      while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
      if (pos_ >= text_.size()) throw VtkFileError(fmt::format("{}: the base64 data end early", where_));
      q[i] = text_[pos_++];
    }
    int s[4], pad = 0;
    for (int i = 0; i < 4; ++i) {
      if (q[i] == '=' && i >= 2) { s[i] = 0; ++pad; continue; }
      s[i] = sextet(q[i]);
      if (s[i] < 0 || pad > 0) throw VtkFileError(fmt::format("{}: '{}' is not base64", where_, std::string(q, 4)));
    }
    const std::uint32_t bits = (std::uint32_t(s[0]) << 18) | (std::uint32_t(s[1]) << 12) | (std::uint32_t(s[2]) << 6) | std::uint32_t(s[3]);
    const char bytes[3] = {char(bits >> 16), char((bits >> 8) & 0xff), char(bits & 0xff)};
    pending_.append(bytes, 3 - pad);
  }

  const std::string& text_;
  std::size_t pos_;
  bool base64_;
  std::string where_, pending_;
};

ValueType xml_type(const std::string& name, const std::string& where) {
  static const std::map<std::string, ValueType> types = {
      {"Float32", {ValueType::floating, 4}},         {"Float64", {ValueType::floating, 8}},
      {"Int8", {ValueType::signed_integer, 1}},      {"Int16", {ValueType::signed_integer, 2}},
      {"Int32", {ValueType::signed_integer, 4}},     {"Int64", {ValueType::signed_integer, 8}},
      {"UInt8", {ValueType::unsigned_integer, 1}},   {"UInt16", {ValueType::unsigned_integer, 2}},
      {"UInt32", {ValueType::unsigned_integer, 4}},  {"UInt64", {ValueType::unsigned_integer, 8}}};
  const auto it = types.find(name);
  if (it == types.end()) throw VtkFileError(fmt::format("{}: type '{}' is not a VTK number type", where, name));
  return it->second;
}

struct XmlLayout {
  bool big_endian = false, compressed = false;
  ValueType header{ValueType::unsigned_integer, 4};
  const std::string* appended = nullptr;  // the appended data after its '_'
  bool appended_base64 = false;
};

// The header-prefixed bytes of a binary array: one header integer (the byte
// count) before plain data; [blocks, block size, last block size, each
// compressed size] before zlib blocks.
std::string binary_bytes(ByteStream& in, const XmlLayout& L, const std::string& where) {
  auto header_value = [&]() { return std::size_t(value_of(in.read(L.header.size).data(), L.header, L.big_endian)); };
  if (!L.compressed) return in.read(header_value());
  const std::size_t blocks = header_value(), block_size = header_value(), last_size = header_value();
  std::vector<std::size_t> sizes(blocks);
  for (std::size_t& s : sizes) s = header_value();
  std::string out;
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::string packed = in.read(sizes[b]);
    uLongf size = (b + 1 == blocks && last_size != 0) ? last_size : block_size;
    std::string block(size, '\0');
    const int rc = uncompress(reinterpret_cast<Bytef*>(block.data()), &size,
                              reinterpret_cast<const Bytef*>(packed.data()), uLong(packed.size()));
    if (rc != Z_OK) throw VtkFileError(fmt::format("{}: zlib block {} does not inflate (zlib error {})", where, b, rc));
    out.append(block.data(), size);
  }
  return out;
}

VtkArray xml_array(const pugi::xml_node& a, const XmlLayout& L, const std::string& file) {
  const std::string name = a.attribute("Name").as_string();
  const std::string where = fmt::format("{}: DataArray '{}'", file, name);
  const std::size_t components = a.attribute("NumberOfComponents").as_ullong(1);
  if (components == 0) throw VtkFileError(fmt::format("{}: NumberOfComponents is 0", where));
  const ValueType type = xml_type(a.attribute("type").as_string(), where);
  const std::string format = a.attribute("format").as_string("ascii");
  VtkArray out;
  if (format == "ascii") {
    out = ascii_values(a.child_value(), where);
  } else if (format == "binary") {
    const std::string text = a.child_value();
    ByteStream in(text, 0, true, where);
    out = binary_array(binary_bytes(in, L, where), type, L.big_endian);
  } else if (format == "appended") {
    if (!L.appended) throw VtkFileError(fmt::format("{}: format appended, but the file has no AppendedData", where));
    if (a.attribute("offset").empty()) throw VtkFileError(fmt::format("{}: format appended needs an offset", where));
    ByteStream in(*L.appended, a.attribute("offset").as_ullong(), L.appended_base64, where);
    out = binary_array(binary_bytes(in, L, where), type, L.big_endian);
  } else {
    throw VtkFileError(fmt::format("{}: format '{}' is none of ascii, binary, appended", where, format));
  }
  out.components = components;
  if (out.values.size() % out.components != 0)
    throw VtkFileError(fmt::format("{}: {} values are not whole tuples of {}", where, out.values.size(), out.components));
  return out;
}

void append(VtkArray& into, const VtkArray& a) {
  into.spacing = into.values.empty() ? a.spacing : std::max(into.spacing, a.spacing);
  into.text = into.values.empty() ? a.text : into.text || a.text;
  into.components = a.components;
  into.values.insert(into.values.end(), a.values.begin(), a.values.end());
}

VtkPoints read_xml(const std::string& path) {
  std::string text = file_bytes(path);
  // The appended data are bytes, not XML: parse the rest, keep them apart.
  std::string appended;
  bool has_appended = false, appended_base64 = false;
  if (const std::size_t tag = text.find("<AppendedData"); tag != std::string::npos) {
    const std::size_t open_end = text.find('>', tag);
    const std::size_t mark = open_end == std::string::npos ? open_end : text.find('_', open_end);
    const std::size_t close = text.rfind("</AppendedData>");
    if (mark == std::string::npos || close == std::string::npos || close < mark)
      throw VtkFileError(fmt::format("{}: AppendedData has no '_' mark or no end tag", path));
    appended_base64 = text.substr(tag, open_end - tag).find("base64") != std::string::npos;
    appended = text.substr(mark + 1, close - mark - 1);
    if (appended_base64) {  // base64 text ends with whitespace before the tag
      while (!appended.empty() && std::isspace(static_cast<unsigned char>(appended.back()))) appended.pop_back();
    }
    text.erase(mark, close - mark);
    has_appended = true;
  }
  pugi::xml_document doc;
  const pugi::xml_parse_result parsed = doc.load_buffer(text.data(), text.size());
  if (!parsed) throw VtkFileError(fmt::format("{}: not XML ({} at byte {})", path, parsed.description(), parsed.offset));
  const pugi::xml_node root = doc.child("VTKFile");
  if (!root) throw VtkFileError(fmt::format("{}: no VTKFile element", path));
  const std::string type = root.attribute("type").as_string();
  if (type != "UnstructuredGrid" && type != "PolyData")
    throw VtkFileError(fmt::format("{}: VTKFile type '{}': particles are read from UnstructuredGrid (.vtu) or PolyData (.vtp)", path, type));
  XmlLayout L;
  L.big_endian = std::string(root.attribute("byte_order").as_string("LittleEndian")) == "BigEndian";
  const std::string header = root.attribute("header_type").as_string("UInt32");
  if (header != "UInt32" && header != "UInt64")
    throw VtkFileError(fmt::format("{}: header_type '{}' is neither UInt32 nor UInt64", path, header));
  L.header.size = header == "UInt64" ? 8 : 4;
  const std::string compressor = root.attribute("compressor").as_string();
  if (!compressor.empty() && compressor != "vtkZLibDataCompressor")
    throw VtkFileError(fmt::format("{}: compressor '{}': mpmvv reads uncompressed or zlib-compressed data (vtkZLibDataCompressor)", path, compressor));
  L.compressed = !compressor.empty();
  if (has_appended) {
    L.appended = &appended;
    L.appended_base64 = appended_base64;
  }
  const pugi::xml_node data = root.child(type.c_str());
  VtkPoints out;
  for (const pugi::xml_node& a : data.child("FieldData").children("DataArray"))
    out.field_data[a.attribute("Name").as_string()] = xml_array(a, L, path);
  std::size_t pieces = 0;
  for (const pugi::xml_node& piece : data.children("Piece")) {
    const std::size_t n = piece.attribute("NumberOfPoints").as_ullong(0);
    const std::string where = fmt::format("{}: Piece {}", path, pieces++);
    const pugi::xml_node points = piece.child("Points").child("DataArray");
    if (!points) throw VtkFileError(fmt::format("{}: no Points", where));
    const VtkArray x = xml_array(points, L, path);
    if (x.components != 3 || x.tuples() != n)
      throw VtkFileError(fmt::format("{}: Points must be {} x 3 (NumberOfPoints), not {} x {}", where, n, x.tuples(), x.components));
    append(out.points, x);
    for (const pugi::xml_node& a : piece.child("PointData").children("DataArray")) {
      const std::string name = a.attribute("Name").as_string();
      const VtkArray v = xml_array(a, L, path);
      if (v.tuples() != n)
        throw VtkFileError(fmt::format("{}: point array '{}' has {} tuples for {} points", where, name, v.tuples(), n));
      if (pieces > 1 && out.point_data.count(name) == 0)
        throw VtkFileError(fmt::format("{}: point array '{}' is not in the pieces before", where, name));
      append(out.point_data[name], v);
    }
    for (const auto& [name, a] : out.point_data)
      if (a.tuples() != out.points.tuples())
        throw VtkFileError(fmt::format("{}: point array '{}' is missing from this piece", where, name));
  }
  if (pieces == 0) throw VtkFileError(fmt::format("{}: no Piece", path));
  return out;
}

// ------------------------------------------------------------- legacy files

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
      if (pos_ + n * t.size > text_.size())
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

VtkPoints read_vtk_points(const std::string& path) {
  const std::string ext = fs::path(path).extension().string();
  if (ext == ".vtu" || ext == ".vtp") return read_xml(path);
  if (ext == ".vtk") return LegacyReader(path).read();
  throw VtkFileError(fmt::format("{}: not a .vtu, .vtp or .vtk file", path));
}

}  // namespace mpmvv::app
