// VTK's XML files (.vtu, .vtp): ascii, inline binary or appended data, raw
// or base64, uncompressed or zlib-compressed, as "VTK File Formats" lays
// them out.
#include <algorithm>
#include <cctype>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <pugixml.hpp>
#include <zlib.h>

#include "vtk_values.hpp"

namespace mpmvv::app::vtk {

namespace {

// The next bytes of a DataArray's data: raw (appended, encoding="raw") or
// base64. VTK encodes a binary array's header and its data as two base64
// runs, each padded on its own, where other writers encode them as one: the
// decoder takes each padded quantum as it comes, so both read the same.
class ByteStream {
 public:
  ByteStream(const std::string& text, std::size_t pos, bool base64, std::string where)
      : text_(text), pos_(pos), base64_(base64), where_(std::move(where)) {}

  // At most how many bytes are left to read.
  std::size_t left() const {
    const std::size_t rest = text_.size() - pos_;
    return base64_ ? pending_.size() + (rest / 4 + 1) * 3 : rest;  // four characters of base64 make three bytes
  }

  std::string read(std::size_t n) {
    if (!base64_) {
      if (n > text_.size() - pos_) throw VtkFileError(fmt::format("{}: the data end before {} more bytes", where_, n));
      std::string out = text_.substr(pos_, n);
      pos_ += n;
      return out;
    }
    if (n > left()) throw VtkFileError(fmt::format("{}: the data end before {} more bytes", where_, n));
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
  // A header read from the file bounds nothing: the sizes must fit in what
  // follows (each block a header integer) before anything is allocated.
  if (blocks > in.left() / L.header.size)
    throw VtkFileError(fmt::format("{}: the header declares {} zlib blocks, more than the data can hold", where, blocks));
  std::vector<std::size_t> sizes(blocks);
  for (std::size_t& s : sizes) s = header_value();
  std::string out;
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::string packed = in.read(sizes[b]);
    uLongf size = (b + 1 == blocks && last_size != 0) ? last_size : block_size;
    // zlib inflates a byte to at most 1032 (its deflate's largest ratio).
    if (size > 1032 * packed.size() + 64)
      throw VtkFileError(fmt::format("{}: zlib block {} declares {} bytes inflated from {}, more than zlib can make",
                                     where, b, size, packed.size()));
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

}  // namespace

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

}  // namespace mpmvv::app::vtk
