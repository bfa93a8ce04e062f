#include "xdmf_file.hpp"

#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "solver/io/hdf5.hpp"
#include "solver/io/write_file.hpp"

namespace mpmvv::app {

namespace fs = std::filesystem;

namespace {

// &, <, > and quotes as XML has them (the file name is the only text).
std::string escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string dims_text(const std::vector<hsize_t>& dims) { return fmt::format("{}", fmt::join(dims, " ")); }

struct Field {
  const char* name;
  const char* type;  // the XDMF AttributeType
};

// One point set at one time: group `path` of the file, its `position`, the
// fields it has of `fields`.
std::string grid_text(const h5::Group& group, const std::string& path, double time, const std::vector<Field>& fields,
                      const std::string& file, hsize_t index_count) {
  const std::vector<hsize_t> points = group.dimensions("position");
  const hsize_t n = points.empty() ? 0 : points[0];
  // A dataset of the group, as doubles.
  auto item = [&](const std::string& dataset, const std::vector<hsize_t>& dims) {
    return fmt::format("<DataItem Dimensions=\"{}\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">{}:{}/{}</DataItem>",
                       dims_text(dims), file, path, dataset);
  };
  // Polyvertex cells, one per particle, from the first n entries of /particle_index.
  std::string s = fmt::format("   <Grid Name=\"t = {:.6g} s\" GridType=\"Uniform\">\n    <Time Value=\"{:.17g}\"/>\n",
                              time, time);
  s += fmt::format("    <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\" NodesPerElement=\"1\">\n"
                   "     <DataItem ItemType=\"HyperSlab\" Dimensions=\"{}\">\n"
                   "      <DataItem Dimensions=\"3 1\" Format=\"XML\">0 1 {}</DataItem>\n"
                   "      <DataItem Dimensions=\"{}\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">{}:/particle_index</DataItem>\n"
                   "     </DataItem>\n    </Topology>\n",
                   n, n, n, index_count, file);
  s += fmt::format("    <Geometry GeometryType=\"XY\">\n     {}\n    </Geometry>\n", item("position", points));
  for (const Field& f : fields) {
    if (!group.has(f.name)) continue;
    s += fmt::format("    <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"Node\">\n     {}\n    </Attribute>\n",
                     f.name, f.type, item(f.name, group.dimensions(f.name)));
  }
  return s + "   </Grid>\n";
}

}  // namespace

std::string xdmf_sidecar_path(const std::string& h5_path) {
  fs::path p(h5_path);
  if (p.extension() == ".h5") return p.replace_extension(".xmf").string();
  return h5_path + ".xmf";
}

std::string xdmf_text(const std::string& h5_path) {
  const h5::File file = h5::File::open_read(h5_path);
  const h5::Group root = file.root();
  const std::string name = escaped(fs::path(h5_path).filename().string());
  const hsize_t index_count = root.has("particle_index") ? root.dimensions("particle_index")[0] : 0;
  if (index_count == 0) throw std::runtime_error(h5_path + ": no /particle_index (written before the sidecar was)");
  const std::vector<Field> snapshot_fields = {{"displacement", "Vector"}, {"velocity", "Vector"},
                                              {"J", "Scalar"},            {"stress", "Matrix"},
                                              {"deformation_gradient", "Matrix"},
                                              {"displacement_error", "Vector"}};
  const std::vector<Field> end_fields = {{"reference_position", "Vector"}, {"velocity", "Vector"},
                                         {"volume", "Scalar"},
                                         {"J", "Scalar"},
                                         {"deformation_gradient", "Matrix"}};
  std::string grids;
  double last = -1.0;
  if (root.has("snapshots")) {
    const h5::Group all = root.open_group("snapshots");
    std::vector<std::string> members = all.members();
    std::sort(members.begin(), members.end(),
              [](const std::string& a, const std::string& b) { return std::stoul(a) < std::stoul(b); });
    for (const std::string& k : members) {
      const h5::Group g = all.open_group(k);
      last = g.attribute_double("time");
      grids += grid_text(g, "/snapshots/" + k, last, snapshot_fields, name, index_count);
    }
  }
  // The end state, unless the last output is it (a run that stopped between
  // outputs adds the state it stopped at).
  const double end = root.attribute_double("time_reached");
  if (end > last) grids += grid_text(root.open_group("particles"), "/particles", end, end_fields, name, index_count);
  return "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n"
         "  <Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n" +
         grids + "  </Grid>\n </Domain>\n</Xdmf>\n";
}

void write_xdmf_sidecar(const std::string& h5_path) {
  const std::string path = xdmf_sidecar_path(h5_path), partial = path + ".partial";
  io::write_file(partial, xdmf_text(h5_path));
  std::error_code ec;
  fs::rename(partial, path, ec);
  if (ec) {
    fs::remove(partial, ec);
    throw std::runtime_error("cannot rename " + partial + ": " + ec.message());
  }
}

}  // namespace mpmvv::app
