// A suite file is read and checked before anything runs: sweeps, zips and
// overrides expand to the cases they name, every mistake is named with its
// file, line and key, published references must match cases, and a read
// where the exact signal is trivial is warned about. The suite is loaded in
// the test's process; nothing runs.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "suite_support.hpp"
#include "tools/app/config.hpp"
#include "tools/app/suite/suite.hpp"

namespace {

using namespace mpmvv::suite_testing;
using mpmvv::app::ConfigError;

std::string config_error(const fs::path& suite) {
  try {
    mpmvv::app::load_suite(suite.string());
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

// Sweep lists form a product (the last key fastest), zipped lists go together,
// overrides reach the cases they match, and ids name the swept values in file
// order.
TEST(SuiteFile, ExpandsSweepZipAndOverrides) {
  const fs::path dir = scratch("expand");
  const fs::path suite = write(dir / "s.toml", "[[study]]\nname = \"r\"\nscene = \"" + kScenes + "/ring.toml\"\n"
                                               "set = { end_time = 0.25 }\n"
                                               "sweep = { method = [\"gimp\", \"cpdi\"], cells = [32, 64] }\n"
                                               "zip = { particles_per_direction = [2, 3], cfl = [0.3, 0.2] }\n"
                                               "[[study.override]]\nwhere = { cells = 64, method = \"cpdi\" }\n"
                                               "set = { probe_points = 11 }\n");
  const mpmvv::app::Suite s = mpmvv::app::load_suite(suite.string());
  ASSERT_EQ(s.cases.size(), 8u);
  EXPECT_EQ(s.cases[0].id, "r-method=gimp-cells=32-particles_per_direction=2-cfl=0.3");
  EXPECT_EQ(s.cases[1].id, "r-method=gimp-cells=32-particles_per_direction=3-cfl=0.2");
  EXPECT_EQ(s.cases[2].id, "r-method=gimp-cells=64-particles_per_direction=2-cfl=0.3");
  EXPECT_EQ(s.cases[7].id, "r-method=cpdi-cells=64-particles_per_direction=3-cfl=0.2");
  int overridden = 0;
  for (const auto& c : s.cases) {
    const bool match = c.keys.at("cells") == 64 && c.keys.at("method") == "cpdi";
    overridden += match;
    EXPECT_EQ(c.keys.at("probe_points"), match ? 11 : 51) << c.id;
    EXPECT_NE(c.configuration.find("end_time = 0.25"), std::string::npos) << c.id;
  }
  EXPECT_EQ(overridden, 2);
}

// A zipped list may repeat a value when the tuples differ (the explicit step
// with two dilatations beside the implicit one).
TEST(SuiteFile, ZipRepeatsAValueInDistinctTuples) {
  const fs::path dir = scratch("zip-repeat");
  const fs::path suite = write(dir / "s.toml", "[[study]]\nname = \"r\"\nscene = \"" + kScenes + "/ring.toml\"\n"
                                               "zip = { method = [\"cpdi\", \"cpdi\", \"gimp\"], cfl = [0.3, 0.2, 0.3] }\n");
  const mpmvv::app::Suite s = mpmvv::app::load_suite(suite.string());
  ASSERT_EQ(s.cases.size(), 3u);
  EXPECT_EQ(s.cases[0].id, "r-method=cpdi-cfl=0.3");
  EXPECT_EQ(s.cases[1].id, "r-method=cpdi-cfl=0.2");
  EXPECT_EQ(s.cases[2].id, "r-method=gimp-cfl=0.3");
}

// Every mistake is one message naming the file, the line and the key, before
// anything runs.
TEST(SuiteFile, MistakesNameFileLineAndKey) {
  const fs::path dir = scratch("mistakes");
  const std::string study = "[[study]]\nname = \"a\"\nscene = \"" + kScenes + "/ring.toml\"\n";
  struct Case {
    std::string text, mentions;
  };
  const Case cases[] = {
      {study + "sweep = { cells = [32, 64], nokey = [1] }\n", "s.toml:4: sweep: unknown key 'nokey'"},
      {study + "sweep = { cells = [32, 2] }\n", "s.toml:4: key 'cells' must be an integer in [4, 20000], got 2"},
      {study + "set = { density = -1 }\n", "s.toml:4: key 'density' must be a number > 0"},
      {study + "zip = { cells = [32, 64], cfl = [0.3] }\n", "zipped lists must be equally long"},
      {study + "foo = 1\n", "s.toml:4: unknown key 'foo' in [[study]]"},
      {study + "set = { cells = 32 }\nsweep = { cells = [32, 64] }\n", "key 'cells' is given twice"},
      {study + "sweep = { cells = [32, 32] }\n", "'cells' lists 32 twice"},
      {study + "zip = { cells = [32, 64, 32], cfl = [0.3, 0.3, 0.3] }\n",
       "s.toml:4: zip: entries 1 and 3 are the same (cells=32, cfl=0.3)"},
      {"[[study]]\nname = \"a\"\nscene = \"nope.toml\"\n", "s.toml:3: study 'a': no such scene file"},
      {study + "[[expect]]\nstudy = \"b\"\nnorm = \"L1\"\norder = 2\ntolerance = 0.1\n", "s.toml:5: [[expect]]: no study named 'b'"},
      {study + "sweep = { cells = [32, 64] }\n[[expect]]\nstudy = \"a\"\nnorm = \"L1_theta0\"\norder = 2\n",
       "[[expect]] needs 'tolerance'"},
      {study + "sweep = { cells = [32, 64] }\n[[expect]]\nstudy = \"a\"\nnorm = \"L1_theta0\"\norder = 2\ntolerance = 0.1\n"
               "levels = [32, 128]\n",
       "study 'a' has no case with cells = 128"},
      {study + "sweep = { cells = [32, 64] }\n[[expect]]\nstudy = \"a\"\nnorm = \"L1_theta0\"\nmax_error = 1.0\n"
               "interval_within_band = true\n",
       "'interval_within_band' needs an 'order'"},
      {study + "sweep = { cells = [32, 64] }\n[[expect]]\nstudy = \"a\"\nnorm = \"L1_theta0\"\norder = nan\n"
               "tolerance = 0.1\n",
       "[[expect]] holds a value that is not a finite number (nan or inf)"},
      {study + "sweep = { cells = [32, 64] }\n[[expect]]\nstudy = \"a\"\nnorm = \"L1_theta0\"\norder = 2\n"
               "tolerance = 0.1\ninterval_within_band = 1\n",
       "'interval_within_band' must be true or false"},
      {study + "sweep = { cells = [32, 64] }\n[[expect]]\nstudy = \"a\"\nnorm = \"L1_theta0\"\norder = 2\n"
               "tolerance = 0.1\nat_roundoff = true\n",
       "'at_roundoff' asks for errors at round-off, where no order can be observed"},
      {study + "sweep = { cells = [32, 64] }\n[[expect]]\nstudy = \"a\"\nnorm = \"L1_theta0\"\nat_roundoff = 1\n",
       "s.toml:8: [[expect]]: 'at_roundoff' must be true or false"},
      {study + "sweep = { cells = [32, 64] }\n[[expect]]\nstudy = \"a\"\nnorm = \"L1_theta0\"\nat_roundoff = false\n",
       "[[expect]] needs 'order' (a number), or 'max_error' or 'at_roundoff = true' alone"},
      // Found at load, not by the gate after every case ran.
      {study + "sweep = { cells = [32, 64] }\n[[expect]]\nstudy = \"a\"\nnorm = \"L1_theta9\"\nmax_error = 1.0\n",
       "s.toml:7: [[expect]]: study 'a' writes no /errors column 'L1_theta9'; its columns: L1_theta0"},
      {study + "sweep = { cells = [32, 64] }\n[[expect]]\nstudy = \"a\"\nnorm = \"L1_theta0\"\ntime = 0.33\n"
               "max_error = 1.0\n",
       "s.toml:8: [[expect]]: t = 0.33 is not an output time of case 'a-cells=32'"},
      {study + "sweep = { cells = [32, 64] }\n[[expect]]\nstudy = \"a\"\nwhere = { method = \"gimp\" }\n"
               "norm = \"L1_theta0\"\nmax_error = 1.0\n",
       "s.toml:5: [[expect]]: where method=gimp matches no case of study 'a'"},
      {study + "sweep = { cells = [32, 64], amplitude = [0.5, 1.0] }\n[[expect]]\nstudy = \"a\"\n"
               "norm = \"L1_theta0\"\nrefine = \"amplitude\"\norder = 2\ntolerance = 0.1\n",
       "'refine' = \"amplitude\" sets no size an order is observed against"},
      {study + "sweep = { cells = [32, 64] }\n[[study.override]]\nwhere = { cells = 128 }\nset = { cfl = 0.2 }\n",
       "study 'a': [[study.override]] 1 where cells=128 matches none of its cases"},
      {study + "sweep = { cells = [32, 64], cfl = [0.1, 0.2, 0.3, 0.4, 0.5], end_time = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7,"
               " 0.8, 0.9, 1.0], amplitude = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0], density = [1.0, 2.0, "
               "3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0] }\n",
       "study 'a' makes 11000 cases (0 before it), more than the 10000 a suite may hold"},
      {study + "set = { inner_radius = 1.3 }\n", "key 'outer_radius': must exceed inner_radius = 1.3 (from"},
      {study + "set = { cells = 16 }\n", "key 'cells': the ring (outer radius 1.25 m) needs two cells of clearance "
                                         "inside the 3 m domain, and cells = 16 makes h = 0.1875 m: use cells >= 24, "
                                         "or a domain over 3.25 m"},
      {study + "set = { domain = 2.4 }\n", "key 'domain': the ring (outer radius 1.25 m) needs two cells of "
                                           "clearance inside the 2.4 m domain"},
      {study + "sweep = { cells = [32, 64] }\n[[reference]]\nsource = \"x\"\nstudy = \"a\"\nquantity = \"time_reached\"\n"
               "columns = [\"cells\"]\nrows = [[32, 0.4], [128, 0.3]]\n",
       "s.toml:10: [[reference]]: the row cells=128 matches no case of study 'a'"},
      {study + "sweep = { cells = [32, 64] }\n[[reference]]\nsource = \"x\"\nstudy = \"a\"\nquantity = \"time_reached\"\n"
               "columns = [\"cels\"]\nrows = [[32, 0.4]]\n",
       "s.toml:9: [[reference]]: column 'cels' is not a key of study 'a'"},
      {study + "[[reference]]\nsource = \"x\"\nstudy = \"a\"\nquantity = \"speed\"\nrows = [[0.4]]\n",
       "s.toml:7: [[reference]] needs 'quantity': \"time_reached\", \"error\" or \"order\""},
      {study + "[[reference]]\nsource = \"x\"\nstudy = \"a\"\nquantity = \"error\"\nrows = [[0.1]]\n",
       "s.toml:4: [[reference]]: an error needs 'norm'"},
      {study + "[[reference]]\nsource = \"x\"\nstudy = \"a\"\nquantity = \"error\"\nnorm = \"particle_L2\"\n"
               "rows = [[-0.1]]\n",
       "the last value of a row is the error, a non-negative number"},
      {study + "[[reference]]\nsource = \"x\"\nstudy = [\"a\", \"b\"]\nquantity = \"order\"\nnorm = \"L1_theta0\"\nrows = [[2.0]]\n",
       "s.toml:6: [[reference]]: no study named 'b'"},
      {study + "[[reference]]\nsource = \"x\"\nstudy = \"a\"\nquantity = \"order\"\nrows = [[2.0]]\n",
       "s.toml:4: [[reference]]: an order needs 'norm'"},
      {study + "[[reference]]\nsource = \"x\"\nstudy = \"a\"\nquantity = \"time_reached\"\ncolumns = [\"cells\"]\n"
               "rows = [[64]]\n",
       "each row holds a value for each of the 1 columns, then the time_reached"},
      {study + "[[reference]]\nstudy = \"a\"\nquantity = \"time_reached\"\nrows = [[-1.0]]\n",
       "s.toml:4: [[reference]] needs a source"},
      {study + "[[reference]]\nsource = \"x\"\nstudy = \"a\"\nquantity = \"time_reached\"\nrows = [[-1.0]]\n",
       "the last value of a row is the time_reached, a non-negative number"},
      {study + "[[reference]]\nsource = \"x\"\nstudy = \"a\"\nquantity = \"time_reached\"\nrows = [[1.0]]\nlevel = 3\n",
       "s.toml:9: unknown key 'level' in [[reference]]"},
      {"[[study]]\nname = \"a b\"\n", "may hold only letters, digits"},
      {"[[study]]\nname = \"" + std::string(240, 'x') + "\"\nscene = \"" + kScenes +
           "/ring.toml\"\nsweep = { cells = [32] }\n",
       "characters long, more than the 244 a file name leaves it"},
      {"[[study]\n", "TOML syntax error"},
      {"checkpoint_every = -5\n" + study, "s.toml:1: 'checkpoint_every' must be a positive, finite number of seconds"},
  };
  for (const Case& c : cases) {
    const std::string message = config_error(write(dir / "s.toml", c.text));
    EXPECT_NE(message.find(c.mentions), std::string::npos) << "message: " << message << "\nexpected: " << c.mentions;
  }
}

// Published numbers beside the suite's own: the shipped Sandia suite's
// [[reference]] tables (table 3.2 and the order of figure 3.5 of
// 000_1dbcb8acb6dddab9.txt) load, every row matching its cases; the same row
// with an amplitude the study does not sweep is refused.
TEST(SuiteFile, ReferencesMatchTheirCases) {
  const std::string sandia = std::string(MPMVV_SOURCE_DIR) + "/suites/ring-sandia.toml";
  EXPECT_EQ(config_error(sandia), "(no error)");
  std::string text = read(sandia);
  const std::string row = "[300, 2, 1.0, 0.47]";
  ASSERT_NE(text.find(row), std::string::npos);
  text.replace(text.find(row), row.size(), "[300, 2, 0.75, 0.47]");
  const fs::path dir = scratch("references");
  fs::copy(std::string(MPMVV_SOURCE_DIR) + "/suites/scenes", dir / "scenes");
  const std::string message = config_error(write(dir / "ring-sandia.toml", text));
  EXPECT_NE(message.find("[[reference]]: the row cells=300, particles_per_direction=2, amplitude=0.75 matches no case of its studies"),
            std::string::npos)
      << message;
}

// An expectation read where the exact signal is trivial (the r-z cylinder at
// t = 1 s, where its exact displacement is zero) is warned about when the
// suite is loaded, before anything runs, naming the file and line; one read
// where the motion is large is not.
TEST(SuiteFile, WarnsOfAReadWhereTheExactSignalIsTrivial) {
  const fs::path dir = scratch("trivial-read");
  const fs::path suite = write(dir / "s.toml", "[[study]]\nname = \"rz\"\nscene = \"" + kScenes +
                                                   "/rz-cylinder.toml\"\nsweep = { cells = [8, 16] }\n"
                                                   "[[expect]]\nstudy = \"rz\"\nnorm = \"particle_L2\"\n"
                                                   "time = 1.0\norder = 2.0\ntolerance = 0.3\n"
                                                   "[[expect]]\nstudy = \"rz\"\nnorm = \"L1_line_z_quarter\"\n"
                                                   "time = 0.25\norder = 2.0\ntolerance = 0.3\n");
  const mpmvv::app::Suite loaded = mpmvv::app::load_suite(suite.string());
  ASSERT_EQ(loaded.warnings.size(), 1u);
  EXPECT_NE(loaded.warnings[0].find("s.toml:5"), std::string::npos) << loaded.warnings[0];
  EXPECT_NE(loaded.warnings[0].find("particle_L2 at t = 1 where the exact signal is 0 %"), std::string::npos)
      << loaded.warnings[0];
}

// A study's ci table takes the place of its own keys in the ci tier: a swept
// key keeps its place in the id, a set key may be swept and a swept one set;
// a study without one is left out; each tier keeps only its expectations.
TEST(SuiteFile, CiTierReplacesTheStudysKeys) {
  const fs::path dir = scratch("ci-tier");
  const fs::path suite = write(
      dir / "s.toml",
      "[[study]]\nname = \"r\"\nscene = \"" + kScenes + "/ring.toml\"\n"
      "set = { end_time = 0.25, particles_per_direction = 2 }\n"
      "sweep = { method = [\"gimp\", \"cpdi\"], cells = [32, 64, 128] }\n"
      "ci = { set = { method = \"cpdi\", end_time = 0.1 }, sweep = { cells = [24, 32], particles_per_direction = [1, 2] } }\n"
      "[[study]]\nname = \"full-only\"\nscene = \"" + kScenes + "/ring.toml\"\nsweep = { cells = [32, 64] }\n"
      "[[expect]]\nstudy = \"r\"\nnorm = \"particle_L2\"\nlevels = [64, 128]\norder = 2.0\ntolerance = 0.5\n"
      "[[expect]]\nstudy = \"r\"\nnorm = \"particle_L2\"\nmax_error = 0.1\ntier = [\"full\", \"ci\"]\n"
      "[[expect]]\nstudy = \"r\"\nnorm = \"L1_theta0\"\nlevels = [24, 32]\norder = 2.0\ntolerance = 0.5\ntier = \"ci\"\n");
  const mpmvv::app::Suite full = mpmvv::app::load_suite(suite.string());
  EXPECT_EQ(full.tier, "full");
  EXPECT_EQ(full.cases.size(), 8u);
  ASSERT_EQ(full.expectations.size(), 2u);
  EXPECT_EQ(full.expectations[0]["order"], 2.0);
  const mpmvv::app::Suite ci = mpmvv::app::load_suite(suite.string(), mpmvv::app::kCiTier);
  EXPECT_EQ(ci.tier, "ci");
  ASSERT_EQ(ci.cases.size(), 4u);
  EXPECT_EQ(ci.cases[0].id, "r-cells=24-particles_per_direction=1");
  EXPECT_EQ(ci.cases[3].id, "r-cells=32-particles_per_direction=2");
  for (const auto& c : ci.cases) {
    EXPECT_EQ(c.keys.at("method"), "cpdi") << c.id;
    EXPECT_EQ(c.keys.at("end_time"), 0.1) << c.id;
  }
  ASSERT_EQ(ci.expectations.size(), 2u);
  EXPECT_EQ(ci.expectations[0]["max_error"], 0.1);
  EXPECT_EQ(ci.expectations[1]["norm"], "L1_theta0");
}

// The ci tier's mistakes are named: an expectation there on a study the tier
// leaves out, levels the tier does not run, an unknown tier; a suite that
// says it has no ci tier is skipped with its reason, and one with no ci
// study is refused.
TEST(SuiteFile, CiTierMistakesAreNamed) {
  const fs::path dir = scratch("ci-mistakes");
  const std::string study = "[[study]]\nname = \"r\"\nscene = \"" + kScenes + "/ring.toml\"\nsweep = { cells = [32, 64] }\n";
  auto ci_error = [&](const std::string& name, const std::string& text) {
    try {
      mpmvv::app::load_suite(write(dir / name, text).string(), mpmvv::app::kCiTier);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_NE(ci_error("left-out.toml", study + "[[expect]]\nstudy = \"r\"\nnorm = \"particle_L2\"\nmax_error = 1.0\ntier = \"ci\"\n")
                .find("no study has a ci tier"),
            std::string::npos);
  const std::string with_ci = study + "ci = { sweep = { cells = [24, 32] } }\n"
                              "[[study]]\nname = \"q\"\nscene = \"" + kScenes + "/ring.toml\"\n";
  EXPECT_NE(ci_error("not-in-tier.toml", with_ci + "[[expect]]\nstudy = \"q\"\nnorm = \"particle_L2\"\nmax_error = 1.0\ntier = \"ci\"\n")
                .find("applies in the ci tier, where study 'q' does not run"),
            std::string::npos);
  EXPECT_NE(ci_error("levels.toml", with_ci + "[[expect]]\nstudy = \"r\"\nnorm = \"particle_L2\"\nlevels = [32, 64]\n"
                                               "order = 2.0\ntolerance = 0.5\ntier = \"ci\"\n")
                .find("study 'r' has no case with cells = 64"),
            std::string::npos);
  const std::string bad_tier = ci_error("bad-tier.toml", with_ci + "[[expect]]\nstudy = \"r\"\nnorm = \"particle_L2\"\n"
                                                                   "max_error = 1.0\ntier = \"quick\"\n");
  EXPECT_NE(bad_tier.find("bad-tier.toml:"), std::string::npos) << bad_tier;
  EXPECT_NE(bad_tier.find("'tier' must be \"full\", \"ci\""), std::string::npos) << bad_tier;
  EXPECT_NE(ci_error("bad-ci.toml", study + "ci = { sweep = { cells = [24] }, levels = [24] }\n").find("levels"), std::string::npos);
  const fs::path skipped = write(dir / "skip.toml", "[ci]\nskip = \"needs another program\"\n" + study);
  try {
    mpmvv::app::load_suite(skipped.string(), mpmvv::app::kCiTier);
    ADD_FAILURE() << "a suite without a ci tier loaded its ci tier";
  } catch (const mpmvv::app::SuiteSkipped& e) {
    EXPECT_NE(std::string(e.what()).find("needs another program"), std::string::npos) << e.what();
  }
  EXPECT_EQ(mpmvv::app::load_suite(skipped.string()).cases.size(), 2u);
}

// Every shipped suite loads in both tiers, and has a ci tier with an
// expectation there, or says why it has none ([ci] skip).
TEST(SuiteFile, EveryShippedSuiteHasACiTier) {
  int suites = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(std::string(MPMVV_SOURCE_DIR) + "/suites")) {
    if (entry.path().extension() != ".toml") continue;
    ++suites;
    const std::string file = entry.path().string();
    const mpmvv::app::Suite full = mpmvv::app::load_suite(file);
    if (!full.ci_skip.empty()) {
      EXPECT_THROW(mpmvv::app::load_suite(file, mpmvv::app::kCiTier), mpmvv::app::SuiteSkipped) << file;
      continue;
    }
    EXPECT_FALSE(full.ci_covers.empty()) << file << ": [ci] covers says what its ci tier checks";
    const mpmvv::app::Suite ci = mpmvv::app::load_suite(file, mpmvv::app::kCiTier);
    EXPECT_FALSE(ci.expectations.empty()) << file << ": a ci tier without an expectation checks nothing";
  }
  EXPECT_GE(suites, 19);
}
