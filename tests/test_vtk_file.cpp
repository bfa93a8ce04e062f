// VTK particle files read for an external program (tools/app/scene/vtk_file.hpp,
// external_format = "vtk"): which VTK component lands in which entry of
// mpmvv's in-plane vectors and tensors, the two ways base64 runs are joined,
// legacy binary (big-endian, the old cell layout), and the messages for what
// cannot be read. tests/external_vtk.py reads whole runs written by meshio.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "tools/app/scene/number_spacing.hpp"
#include "tools/app/scene/particle_output.hpp"
#include "tools/app/scene/vtk_file.hpp"

namespace {

namespace fs = std::filesystem;
using mpmvv::app::OutputState;
using mpmvv::app::ParticleOutput;
using mpmvv::app::ParticleOutputError;
using mpmvv::app::read_vtk_points;
using mpmvv::app::VtkFileError;
namespace app = mpmvv::app;

fs::path folder(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "mpmvv-vtk-test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void write(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::string base64(const std::string& bytes) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t bits = 0;
    for (std::size_t k = 0; k < 3; ++k)
      bits = (bits << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k) out += k <= n ? digits[(bits >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

template <class T>
std::string bytes_of(const std::vector<T>& v, bool big_endian = false) {
  std::string out;
  for (const T& x : v) {
    char b[sizeof(T)];
    std::memcpy(b, &x, sizeof(T));
    if (big_endian) std::reverse(b, b + sizeof(T));
    out.append(b, sizeof(T));
  }
  return out;
}

// Two particles, every optional field in the layout a 3D code writes, in the
// plane (the third components of velocity, F and stress vanish; the points'
// z, 0 and 7, is free: reference_position has 2 components).
const char* kPolyData = R"(<?xml version="1.0"?>
<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian">
<PolyData>
<FieldData><DataArray type="Float64" Name="TimeValue" NumberOfTuples="1" format="ascii">0.4999</DataArray></FieldData>
<Piece NumberOfPoints="2" NumberOfVerts="0">
<Points><DataArray type="Float32" NumberOfComponents="3" format="ascii">1.5 2.5 0  3.5 4.5 7</DataArray></Points>
<PointData>
<DataArray type="Float64" Name="reference_position" NumberOfComponents="2" format="ascii">1 2 3 4</DataArray>
<DataArray type="Int32" Name="reference_volume" format="ascii">2 5</DataArray>
<DataArray type="Float64" Name="velocity" NumberOfComponents="3" format="ascii">0.1 0.2 0  0.4 0.5 0</DataArray>
<DataArray type="Float64" Name="stress" NumberOfComponents="6" format="ascii">11 22 33 12 0 0  -11 -22 -33 -12 0 0</DataArray>
<DataArray type="Float64" Name="deformation_gradient" NumberOfComponents="9" format="ascii">
  1.1 1.2 0 2.1 2.2 0 0 0 1   5.1 5.2 0 6.1 6.2 0 0 0 1</DataArray>
</PointData>
</Piece>
</PolyData>
</VTKFile>
)";

TEST(VtkFile, ComponentsLandInTheirInPlaceEntries) {
  const fs::path dir = folder("components");
  write(dir / "particles_0.vtp", kPolyData);
  const std::optional<OutputState> s = ParticleOutput(dir.string(), "vtk", {0.5}).read(0, 0);
  ASSERT_TRUE(s);
  ASSERT_EQ(s->P.size(), 2u);
  EXPECT_EQ(s->time, 0.4999);  // TimeValue, within a hundredth of the gap
  EXPECT_EQ(s->P.position[1].x(), 3.5);  // z dropped
  EXPECT_EQ(s->P.position[1].y(), 4.5);
  EXPECT_EQ(s->P.reference_position[1].y(), 4.0);
  EXPECT_EQ(s->P.reference_volume[1], 5.0);  // an integer array read as numbers
  EXPECT_EQ(s->P.velocity[0].y(), 0.2);
  // VTK's symmetric order xx, yy, zz, xy, yz, xz.
  EXPECT_EQ(s->P.stress[0](0, 0), 11.0);
  EXPECT_EQ(s->P.stress[0](1, 1), 22.0);
  EXPECT_EQ(s->P.stress[0](0, 1), 12.0);
  EXPECT_EQ(s->P.stress[1](1, 0), -12.0);
  // A full tensor row-major: F12 is the second value, F21 the fourth.
  EXPECT_EQ(s->P.deformation_gradient[0](0, 1), 1.2);
  EXPECT_EQ(s->P.deformation_gradient[0](1, 0), 2.1);
  EXPECT_EQ(s->P.deformation_gradient[1](1, 1), 6.2);
  EXPECT_TRUE(s->fields.stress && s->fields.deformation_gradient && s->fields.velocity);
  EXPECT_FALSE(s->fields.mass || s->fields.volume || s->fields.J);
}

TEST(VtkFile, Base64HeaderAndDataReadTheSameJoinedOrApart) {
  // VTK encodes an inline binary array's header and data as two runs (each
  // padded); other writers encode them as one.
  const std::vector<double> values = {0.125, -3.0, 1e-300, 7.0, 2.5, 1.0 / 3.0};
  const std::string data = bytes_of(values);
  const std::string header = bytes_of(std::vector<std::uint32_t>{std::uint32_t(data.size())});
  for (const std::string& encoded : {base64(header) + base64(data), base64(header + data)}) {
    const fs::path path = folder("base64") / "p.vtu";
    write(path, "<VTKFile type=\"UnstructuredGrid\" byte_order=\"LittleEndian\"><UnstructuredGrid>"
                "<Piece NumberOfPoints=\"2\"><Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" "
                "format=\"binary\">\n  " + encoded + "\n</DataArray></Points></Piece></UnstructuredGrid></VTKFile>");
    const auto v = read_vtk_points(path.string());
    EXPECT_EQ(v.points.values, values) << encoded;
  }
}

TEST(VtkFile, LegacyBinaryIsBigEndianWithTheOldCellLayout) {
  std::string text = "# vtk DataFile Version 3.0\nparticles\nBINARY\nDATASET UNSTRUCTURED_GRID\n";
  text += "POINTS 2 float\n" + bytes_of(std::vector<float>{1, 2, 0, 3, 4, 0}, true) + "\n";
  text += "CELLS 2 4\n" + bytes_of(std::vector<std::int32_t>{1, 0, 1, 1}, true) + "\n";
  text += "CELL_TYPES 2\n" + bytes_of(std::vector<std::int32_t>{1, 1}, true) + "\n";
  text += "CELL_DATA 2\nSCALARS dropped int 1\nLOOKUP_TABLE default\n" +
          bytes_of(std::vector<std::int32_t>{9, 9}, true) + "\n";
  text += "POINT_DATA 2\nSCALARS reference_volume double 1\nLOOKUP_TABLE default\n" +
          bytes_of(std::vector<double>{0.25, 0.75}, true) + "\n";
  text += "TENSORS stress double\n" +
          bytes_of(std::vector<double>{1, 2, 0, 2, 3, 0, 0, 0, 9, 4, 5, 0, 5, 6, 0, 0, 0, 9}, true) + "\n";
  const fs::path path = folder("legacy") / "p.vtk";
  write(path, text);
  const auto v = read_vtk_points(path.string());
  EXPECT_EQ(v.points.values, (std::vector<double>{1, 2, 0, 3, 4, 0}));
  ASSERT_EQ(v.point_data.count("reference_volume"), 1u);
  EXPECT_EQ(v.point_data.at("reference_volume").values, (std::vector<double>{0.25, 0.75}));
  EXPECT_EQ(v.point_data.at("stress").components, 9u);
  EXPECT_EQ(v.point_data.at("stress").values[12], 5.0);
  EXPECT_EQ(v.point_data.count("dropped"), 0u);  // cell data is read past
}

// The message of what read_vtk_points refuses.
std::string refusal(const std::string& name, const std::string& text) {
  const fs::path path = folder("refused") / name;
  write(path, text);
  try {
    read_vtk_points(path.string());
  } catch (const VtkFileError& e) {
    return e.what();
  }
  return "(read)";
}

TEST(VtkFile, WhatCannotBeReadIsNamed) {
  const std::string open = "<VTKFile type=\"UnstructuredGrid\"";
  const std::string piece = "><UnstructuredGrid><Piece NumberOfPoints=\"1\"><Points>";
  EXPECT_NE(refusal("a.vtu", open + " compressor=\"vtkLZ4DataCompressor\"" + piece +
                                 "</Points></Piece></UnstructuredGrid></VTKFile>")
                .find("compressor 'vtkLZ4DataCompressor'"),
            std::string::npos);
  EXPECT_NE(refusal("b.vtu", open + piece + "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"appended\" "
                                           "offset=\"0\"/></Points></Piece></UnstructuredGrid><AppendedData "
                                           "encoding=\"raw\">_" + std::string("\x08\x00\x00\x00\x01\x02", 6) +
                                           "</AppendedData></VTKFile>")
                .find("the data end before 8 more bytes"),
            std::string::npos);
  EXPECT_NE(refusal("c.vtu", open + piece + "<DataArray type=\"Float64\" NumberOfComponents=\"2\" format=\"ascii\">1 2"
                                           "</DataArray></Points></Piece></UnstructuredGrid></VTKFile>")
                .find("Points must be 1 x 3"),
            std::string::npos);
  EXPECT_NE(refusal("d.vtu", "<VTKFile type=\"ImageData\"></VTKFile>").find("type 'ImageData'"), std::string::npos);
  EXPECT_NE(refusal("e.vtk", "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\n").find("STRUCTURED_POINTS"),
            std::string::npos);
  EXPECT_NE(refusal("f.vtk", "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 double\n1 2 3 4 x 6\n")
                .find("'x' is not a number"),
            std::string::npos);
  EXPECT_NE(refusal("g.txt", "").find("not a .vtu, .vtp or .vtk file"), std::string::npos);
  // A vector of 5 components is no vector of the plane.
  const fs::path dir = folder("width");
  std::string bad = kPolyData;
  const std::string three = "Name=\"velocity\" NumberOfComponents=\"3\"";
  bad.replace(bad.find(three), three.size(), "Name=\"velocity\" NumberOfComponents=\"2\"");
  write(dir / "particles_0.vtp", bad);
  try {
    ParticleOutput(dir.string(), "vtk", {0.5}).read(0, 0);
    ADD_FAILURE() << "a 3-tuple velocity read as 2 x 3";
  } catch (const ParticleOutputError& e) {
    EXPECT_NE(std::string(e.what()).find("point array 'velocity' has 3 tuples for 2 points"), std::string::npos) << e.what();
  }
}

TEST(NumberSpacing, DigitsAsWrittenAndTypesAsStored) {
  EXPECT_EQ(app::significant_digits("-1.25000e-3"), 6);  // trailing zeros are written precision
  EXPECT_EQ(app::significant_digits("0.000120"), 3);     // leading zeros are not
  EXPECT_EQ(app::significant_digits("7"), 1);
  EXPECT_EQ(app::significant_digits("+12.5E+07"), 3);
  EXPECT_EQ(app::significant_digits("0.00"), 0);
  EXPECT_DOUBLE_EQ(app::digits_spacing(6), 1e-5);
  EXPECT_DOUBLE_EQ(app::digits_spacing(12), 1e-11);
  EXPECT_EQ(app::digits_spacing(17), app::kDoubleSpacing);  // 1e-16 is finer than a double
  EXPECT_EQ(app::digits_spacing(0), app::kDoubleSpacing);   // every number was zero
  EXPECT_EQ(app::binary_spacing(true, 8, {}), app::kDoubleSpacing);
  EXPECT_EQ(app::binary_spacing(true, 4, {}), std::ldexp(1.0, -23));
  EXPECT_EQ(app::binary_spacing(false, 4, {3.0, -250.0, 4.0}), 1.0 / 250.0);
  EXPECT_EQ(app::binary_spacing(false, 2, {0.0}), 1.0);
}

TEST(VtkFile, ArraysKeepTheSpacingTheyWereWrittenWith) {
  const fs::path dir = folder("spacing");
  write(dir / "particles_0.vtp", kPolyData);
  const auto v = read_vtk_points((dir / "particles_0.vtp").string());
  EXPECT_DOUBLE_EQ(v.points.spacing, 0.1);                       // "1.5": 2 digits
  EXPECT_DOUBLE_EQ(v.point_data.at("reference_volume").spacing, 1.0);  // "2", "5": one digit
  // The state's spacing is the coarsest of what the norms difference
  // (positions, velocity, stress, F; not the volumes): the velocity's "0.1",
  // one digit, 1.
  const std::optional<OutputState> s = ParticleOutput(dir.string(), "vtk", {0.5}).read(0, 0);
  ASSERT_TRUE(s);
  EXPECT_DOUBLE_EQ(s->output_spacing, 1.0);
}

TEST(ParticleOutput, LatticeReferencePositionsTakeTheCurrentOnesDigits) {
  // Karamelo's dumps as its adapter writes them: X on the seeding lattice
  // (4 digits at most), x and the velocity with 6: the writer's 6 digits,
  // spacing 1e-5, not the lattice's 1e-3; V0 in 17 digits weighs nothing.
  const fs::path dir = folder("lattice");
  write(dir / "particles_0.csv", "X,Y,x,y,V0,vx,vy\n"
                                 "-1.225,-0.225,-1.22446,-0.226121,0.0025000000000000001,-0.0937509,1.1132\n"
                                 "-1.225,-0.175,-1.22448,-0.177112,0.0025000000000000001,-0.0331417,0.743857\n");
  const std::optional<OutputState> s = ParticleOutput(dir.string(), "csv", {0.5}).read(0, 0);
  ASSERT_TRUE(s);
  EXPECT_DOUBLE_EQ(s->output_spacing, 1e-5);
}

// What read() says of `text` as an output's particles file `name`; "(read)" when it reads.
std::string read_message(const std::string& name, const std::string& text) {
  const fs::path dir = folder("plane");
  write(dir / name, text);
  try {
    ParticleOutput(dir.string(), "vtk", {0.5}).read(0, 0);
  } catch (const ParticleOutputError& e) {
    return e.what();
  }
  return "(read)";
}

// kPolyData with the first occurrence of `from` replaced by `to`.
std::string changed(const std::string& from, const std::string& to) {
  std::string text = kPolyData;
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

TEST(VtkFile, OnlyThePlaneIsRead) {
  const auto refused = [](const std::string& message, const std::string& what) {
    const bool found = message.find("is not plane strain: " + what) != std::string::npos;
    if (!found) ADD_FAILURE() << message;
    return found;
  };
  // Each third component that does not vanish is named; each array written
  // here with 6 digits (spacing 1e-5: tolerance 8e-5 of its largest in-plane
  // magnitude; kPolyData's 1 and 2 digits would resolve nothing).
  EXPECT_TRUE(refused(read_message("particles_0.vtp", changed("0.4 0.5 0<", "0.4 0.5 0.0100000<")),
                      "v_z is 0.01 at particle 1"));
  EXPECT_TRUE(refused(read_message("particles_0.vtp", changed("11 22 33 12 0 0", "11 22 33 12 0 1.00000")),
                      "sigma_xz is 1"));
  EXPECT_TRUE(refused(read_message("particles_0.vtp", changed("11 22 33 12 0 0", "11 22 33 12 2.00000 0")),
                      "sigma_yz is 2"));
  EXPECT_TRUE(refused(read_message("particles_0.vtp", changed("5.1 5.2 0 6.1 6.2 0 0 0 1", "5.1 5.2 0 6.1 6.2 0 0 0 1.10000")),
                      "F_33 - 1 is 0.1"));
  EXPECT_TRUE(refused(read_message("particles_0.vtp", changed("1.1 1.2 0 2.1", "1.1 1.2 0.200000 2.1")), "F_13 is 0.2"));
  // A double's round-off out of the plane is no motion: within 1e-9.
  EXPECT_EQ(read_message("particles_0.vtp", changed("6.2 0 0 0 1", "6.2 0 0 0 1.00000000001")), "(read)");
  // A 3-component reference position: z must stay Z (a slab moved out of the
  // plane as a whole is still plane strain; a bent one is not).
  const std::string Z = changed("NumberOfComponents=\"2\" format=\"ascii\">1 2 3 4",
                                "NumberOfComponents=\"3\" format=\"ascii\">1.00000 2 0 3 4 7");
  EXPECT_EQ(read_message("particles_0.vtp", Z), "(read)");
  std::string bent = Z;
  bent.replace(bent.find("3.5 4.5 7"), 9, "3.5 4.5 7.50000");
  EXPECT_TRUE(refused(read_message("particles_0.vtp", bent), "z - Z is 0.5 at particle 1"));
  // Floats: 8 spacings (2^-23) of the largest in-plane magnitude pass, 1e-3 of it does not.
  const auto floats = [](float vz) {
    return changed("type=\"Float64\" Name=\"velocity\" NumberOfComponents=\"3\" format=\"ascii\">0.1 0.2 0  0.4 0.5 0",
                   "type=\"Float32\" Name=\"velocity\" NumberOfComponents=\"3\" format=\"binary\">" +
                       base64(bytes_of(std::vector<std::uint32_t>{24}) +
                              bytes_of(std::vector<float>{0.1f, 0.2f, vz, 0.4f, 0.5f, 0.0f})));
  };
  EXPECT_EQ(read_message("particles_0.vtp", floats(1e-7f)), "(read)");
  EXPECT_TRUE(refused(read_message("particles_0.vtp", floats(5e-4f)), "v_z is 0.0005"));
}

TEST(OutputNames, EachLayoutMapsItsOwnItems) {
  using mpmvv::app::parse_output_names;
  const auto csv = parse_output_names(" V0 = vol , vx=u,vy=v,", "csv");
  EXPECT_EQ(csv.at("V0"), "vol");
  EXPECT_EQ(csv.at("vy"), "v");
  EXPECT_EQ(csv.size(), 3u);
  EXPECT_TRUE(parse_output_names("", "hdf5").empty());
  EXPECT_EQ(parse_output_names("tracer_position=tracers", "hdf5").at("tracer_position"), "tracers");
  const auto message = [](const std::string& text, const std::string& format) {
    try {
      parse_output_names(text, format);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(parsed)");
  };
  // A CSV has columns, VTK has no named positions.
  EXPECT_NE(message("reference_volume=vol", "csv").find("not an item of the csv layout, whose names are X, Y"),
            std::string::npos);
  EXPECT_NE(message("position=pos", "vtk").find("(the positions are the points)"), std::string::npos);
  EXPECT_NE(message("mass=", "vtk").find("'mass' is given no file name"), std::string::npos);
  EXPECT_NE(message("mass=m, mass=n", "vtk").find("'mass' is named twice"), std::string::npos);
}

// A stress written in Voigt's order (xx, yy, zz, yz, xz, xy) is read, and its
// plane checked, where external_stress_order puts the components: the same
// particles as kPolyData's VTK order, and a yz shear out of the plane named
// as sigma_yz from its Voigt place.
TEST(StressOrder, ComponentsAreReadWhereTheOrderPutsThem) {
  using mpmvv::app::parse_stress_order;
  const app::StressOrder voigt = parse_stress_order(" xx, yy ,zz, zy, XZ, yx");
  EXPECT_EQ(voigt, (app::StressOrder{0, 1, 2, 5, 3, 4}));
  EXPECT_EQ(parse_stress_order("xx,yy,zz,xy,yz,xz"), app::kVtkStressOrder);
  const fs::path dir = folder("voigt");
  // Written with 6 digits, so that a misplaced shear resolves (tolerance 8e-5 of the in-plane magnitudes).
  write(dir / "particles_0.vtp", changed("11 22 33 12 0 0  -11 -22 -33 -12 0 0",
                                         "11.0000 22.0000 33.0000 0 0 12.0000  -11.0000 -22.0000 -33.0000 0 0 -12.0000"));
  const std::optional<OutputState> s = ParticleOutput(dir.string(), "vtk", {0.5}, {}, voigt).read(0, 0);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->P.stress[0](0, 1), 12.0);
  EXPECT_EQ(s->P.stress[0](1, 0), 12.0);
  EXPECT_EQ(s->P.stress[1](0, 1), -12.0);
  EXPECT_EQ(s->P.stress[1](1, 1), -22.0);
  // Read in VTK's order, the same file's xy (its last place) is VTK's xz:
  // out of the plane, and refused.
  try {
    ParticleOutput(dir.string(), "vtk", {0.5}).read(0, 0);
    ADD_FAILURE() << "a Voigt stress read in VTK's order was accepted";
  } catch (const ParticleOutputError& e) {
    EXPECT_NE(std::string(e.what()).find("is not plane strain: sigma_xz is 12"), std::string::npos) << e.what();
  }
  write(dir / "particles_0.vtp", changed("11 22 33 12 0 0  -11 -22 -33 -12 0 0",
                                         "11.0000 22.0000 33.0000 2.00000 0 12.0000  -11.0000 -22.0000 -33.0000 0 0 -12.0000"));
  try {
    ParticleOutput(dir.string(), "vtk", {0.5}, {}, voigt).read(0, 0);
    ADD_FAILURE() << "a yz shear out of the plane was accepted";
  } catch (const ParticleOutputError& e) {
    EXPECT_NE(std::string(e.what()).find("is not plane strain: sigma_yz is 2 at particle 0"), std::string::npos)
        << e.what();
  }
  const auto message = [&](const std::string& text) {
    try {
      parse_stress_order(text);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(parsed)");
  };
  EXPECT_NE(message("xx, yy, zz, xy, yz, xy").find("xy is given twice (places 4 and 6)"), std::string::npos);
  EXPECT_NE(message("xx, yy, zz, xy, yz").find("xz is missing"), std::string::npos);
  EXPECT_NE(message("xx, yy, zz, xy, yz, xz, xx").find("xx is given twice"), std::string::npos);
  EXPECT_NE(message("s11, yy, zz, xy, yz, xz").find("'s11' (place 1) is not a stress component"), std::string::npos);
  EXPECT_NE(message("").find("'' (place 1) is not a stress component"), std::string::npos);
}

}  // namespace
