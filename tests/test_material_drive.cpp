// The material-point driver (`mpmvv material drive`) and the exact stresses it
// compares with (analytic/principal_stress.hpp).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "analytic/f_tables.hpp"
#include "analytic/principal_stress.hpp"
#include "solver/material/mooney_rivlin.hpp"
#include "solver/material/neo_hookean.hpp"
#include "tools/app/material_drive.hpp"

namespace {

namespace fs = std::filesystem;
using mpmvv::analytic::Deformation;

struct Drive {
  int status;
  std::string out, err;
  nlohmann::json json;
};

Drive drive(mpmvv::app::MaterialDriveRequest request) {
  const fs::path file = fs::temp_directory_path() / ("mpmvv_drive_" + std::to_string(::getpid()) + ".json");
  request.json = file.string();
  std::ostringstream out, err;
  const int status = mpmvv::app::material_drive(request, out, err);
  nlohmann::json j;
  if (status != 2) j = nlohmann::json::parse(std::ifstream(file));
  fs::remove(file);
  return {status, out.str(), err.str(), j};
}

const nlohmann::json& row(const Drive& d, const std::string& material, const std::string& table, double degrees) {
  for (const auto& r : d.json["rows"])
    if (r["material"] == material && r["table"] == table && r["rotation_degrees"] == degrees) return r;
  throw std::runtime_error("no row " + material + " " + table);
}

Deformation random_deformation(std::mt19937& rng, bool out_of_plane) {
  std::uniform_real_distribution<double> d(-0.4, 0.4);
  Deformation D;
  D.F << 1.0 + d(rng), d(rng), d(rng), 1.0 + d(rng);
  D.F33 = out_of_plane ? 1.0 + d(rng) : 1.0;
  return D;
}

// The principal-stretch forms, written from the energies, equal the solver's
// stresses and energies computed from B at random states (plane strain and
// with an out-of-plane stretch), and tell a shear modulus 0.1 % off.
TEST(PrincipalStress, EqualsTheMaterialsStressAndEnergy) {
  const mpmvv::NeoHookean neo{577.0, 385.0};
  const mpmvv::MooneyRivlin mooney{115.5, 77.0, 833.7};
  const mpmvv::analytic::NeoHookeanStretches neo_exact{577.0, 385.0};
  const mpmvv::analytic::MooneyRivlinStretches mooney_exact{115.5, 77.0, 833.7};
  std::mt19937 rng(11);
  int compared = 0;
  for (int k = 0; k < 200; ++k) {
    const Deformation D = random_deformation(rng, k % 2);
    if (!(D.F.determinant() > 0.2)) continue;
    const auto check = [&](const auto& material, const auto& exact, const char* name) {
      const auto s = material.stress(D.F, D.F33);
      const auto e = mpmvv::analytic::principal_stress(exact, D);
      const double scale = 1.0 + s.in_plane.cwiseAbs().maxCoeff();
      EXPECT_LT((s.in_plane - e.in_plane).cwiseAbs().maxCoeff(), 1e-12 * scale) << name << "\n" << D.F;
      EXPECT_NEAR(s.out_of_plane, e.out_of_plane, 1e-12 * scale) << name;
      EXPECT_NEAR(material.energy_density(D.F, D.F33), mpmvv::analytic::principal_energy(exact, D), 1e-12 * scale)
          << name;
    };
    check(neo, neo_exact, "neo-hookean");
    check(mooney, mooney_exact, "mooney-rivlin");
    ++compared;
  }
  EXPECT_GT(compared, 100);
  const Deformation shear = mpmvv::analytic::standard_f_tables()[2].at(1.0);
  const double off = (mpmvv::NeoHookean{577.0, 385.0 * 1.001}.stress(shear.F, 1.0).in_plane -
                      mpmvv::analytic::principal_stress(neo_exact, shear).in_plane)
                         .cwiseAbs()
                         .maxCoeff();
  EXPECT_GT(off, 1e-4 * 385.0);
}

// Every material passes every check that applies on every standard table, and
// the small-strain solid's rotated rows measure the rotation it does not
// follow (a 90 degree turn is of the order of the stress itself) without
// failing the run: it claims no objectivity.
TEST(MaterialDrive, EveryMaterialPassesAndTheSmallStrainSolidIsNotObjective) {
  const Drive d = drive({});
  ASSERT_EQ(d.status, 0) << d.out << d.err;
  EXPECT_EQ(d.json["rows"].size(), 3u * mpmvv::analytic::standard_f_tables().size() * 2u);
  for (const auto& r : d.json["rows"]) {
    EXPECT_LT(r["derivative_error"].get<double>(), 1e-12) << r.dump();
    EXPECT_LT(r["work_error"].get<double>(), 1e-10) << r.dump();
    if (r["material"] != "linear-elastic") {
      EXPECT_LT(r["stress_error"].get<double>(), 1e-13) << r.dump();
      EXPECT_LT(r["energy_error"].get<double>(), 1e-13) << r.dump();
      if (r["rotation_degrees"] != 0.0) {
        EXPECT_LT(r["objectivity_error"].get<double>(), 1e-13) << r.dump();
      }
    } else {
      EXPECT_TRUE(r["stress_error"].is_null());
    }
  }
  const auto& turned = row(d, "linear-elastic", "uniaxial-strain", 90.0);
  EXPECT_GT(turned["objectivity_error"].get<double>(), 0.3);
  EXPECT_EQ(turned["verdict"], "pass; not objective (small strain)");
  EXPECT_NE(d.out.find("PASS: every check within tolerance"), std::string::npos);
}

// The work the stress does along a path converges to the stored energy at
// Simpson's fourth order in the sampling: with 4 times fewer samples the
// work error of the Mooney-Rivlin solid under rotated simple shear grows
// about 256 times; with 5 samples it fails a tight tolerance (exit 1).
TEST(MaterialDrive, WorkAlongThePathConvergesAtFourthOrder) {
  mpmvv::app::MaterialDriveRequest fine, coarse;
  fine.materials = coarse.materials = {"mooney-rivlin"};
  fine.tables = coarse.tables = {"simple-shear"};
  fine.steps = 64;
  coarse.steps = 16;
  const double e_fine = row(drive(fine), "mooney-rivlin", "simple-shear", 90.0)["work_error"];
  const double e_coarse = row(drive(coarse), "mooney-rivlin", "simple-shear", 90.0)["work_error"];
  EXPECT_NEAR(std::log(e_coarse / e_fine) / std::log(4.0), 4.0, 0.3) << e_coarse << " " << e_fine;
  coarse.steps = 4;
  coarse.tolerance = 1e-12;
  const Drive d = drive(coarse);
  EXPECT_EQ(d.status, 1);
  EXPECT_NE(d.out.find("FAIL: work"), std::string::npos) << d.out;
}

// A table file drives the materials like a standard table; its mistakes are
// named with the file and line, and unknown materials and tables are refused.
TEST(MaterialDrive, TableFilesAndBadInput) {
  const fs::path file = fs::temp_directory_path() / ("mpmvv_ftable_" + std::to_string(::getpid()) + ".txt");
  {
    std::ofstream f(file);
    f << "# s F11 F12 F21 F22 F33\n0 1 0 0 1\n0.5, 1.2, 0.1, 0, 0.95, 1.1\n1 1.4 0.2 0 0.9 1.2\n";
  }
  mpmvv::app::MaterialDriveRequest r;
  r.tables = {file.string()};
  const Drive ok = drive(r);
  EXPECT_EQ(ok.status, 0) << ok.out << ok.err;
  EXPECT_EQ(ok.json["rows"].size(), 6u);
  EXPECT_LT(row(ok, "neo-hookean", file.filename().string(), 90.0)["objectivity_error"].get<double>(), 1e-13);

  auto refused = [&](const std::string& text, const std::string& message) {
    {
      std::ofstream f(file);
      f << text;
    }
    const Drive d = drive(r);
    EXPECT_EQ(d.status, 2) << text;
    EXPECT_NE(d.err.find(message), std::string::npos) << d.err;
  };
  refused("0 1 0 0 1\n1 -1 0 0 1\n", file.string() + ":2: J = det F = -1 is not positive");
  refused("0 1 0 0 1\n0 1.1 0 0 1\n", ":2: s = 0 does not increase");
  refused("0 1 0 0 1\n1 1.1 0 0\n", ":2: 4 numbers");
  refused("0 1 0 0 1\n1 1.1 x 0 1\n", ":2: 'x' is not a finite number");
  refused("0 1 0 0 1\n", "at least two rows");
  refused("0 1 0 0 1\n1 -1 0 0 -1\n", "J = 0 at s = 0.5 (F is linear in s between rows)");
  fs::remove(file);

  mpmvv::app::MaterialDriveRequest bad;
  bad.materials = {"steel"};
  EXPECT_NE(drive(bad).err.find("--material 'steel': unknown"), std::string::npos);
  bad = {};
  bad.tables = {"twist"};
  EXPECT_NE(drive(bad).err.find("--table 'twist': neither a standard F-table"), std::string::npos);
  bad = {};
  bad.overrides = {"mu=-1"};
  EXPECT_EQ(drive(bad).status, 2);
}

}  // namespace
