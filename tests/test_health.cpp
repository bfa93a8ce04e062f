// The health verdict (tools/app/scene/health.hpp): each rule marks a run lost at the
// first output time it fails, a run within every rule stays healthy, and
// `mpmvv run` writes a lost run as status "lost" with exit status 1.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>

#include "solver/io/hdf5.hpp"
#include "tools/app/scene/health.hpp"
#include "tools/app/scene/scene.hpp"

namespace {

using mpmvv::Vec2;
using mpmvv::app::ErrorTable;
using mpmvv::app::HealthRules;
using mpmvv::app::HealthSample;
using mpmvv::app::judge_health;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Three output times of a run within every rule: J / J_exact in [0.5, 2],
// an error a tenth of the motion, a little energy lost.
struct Record {
  std::vector<HealthSample> samples;
  ErrorTable errors;
  Record() {
    for (int k = 0; k < 3; ++k) {
      const double t = 0.1 * (k + 1);
      samples.push_back({t, 0.5, 2.0, Vec2(1.0, 0.0), -0.1, 10.0});
      errors.time.push_back(t);
    }
    errors.add_column("L1_line") = {1e-3, 2e-3, 3e-3};
    errors.add_column("particle_L2") = {0.01, 0.02, 0.03};
    errors.add_column("exact_displacement_L2") = {0.1, 0.3, 0.2};
  }
};

}  // namespace

TEST(Health, ARunWithinEveryRuleIsHealthy) {
  const Record r;
  const auto h = judge_health(r.samples, r.errors, HealthRules{});
  EXPECT_FALSE(h.lost);
  EXPECT_TRUE(h.reason.empty());
  EXPECT_TRUE(std::isnan(h.time));
  EXPECT_FALSE(h.reference_position);
  // Energy made is the blow-up stop's business, not this verdict's.
  Record made;
  made.samples[2].energy_created = 1e6;
  EXPECT_FALSE(judge_health(made.samples, made.errors, HealthRules{}).lost);
}

TEST(Health, JOutsideItsBandIsLostAtTheFirstTimeWithTheParticle) {
  for (const auto& [low, high] : {std::pair{0.049, 1.0}, std::pair{1.0, 20.5}, std::pair{kNaN, kNaN}}) {
    Record r;
    r.samples[1].min_J_ratio = low;
    r.samples[1].max_J_ratio = high;
    r.samples[1].worst_J_reference = Vec2(0.8, 0.3);
    r.samples[2].min_J_ratio = 1e-6;  // later and worse: the first time is named
    const auto h = judge_health(r.samples, r.errors, HealthRules{});
    ASSERT_TRUE(h.lost) << low << " " << high;
    EXPECT_DOUBLE_EQ(h.time, 0.2);
    EXPECT_NE(h.reason.find("J / J_exact"), std::string::npos) << h.reason;
    EXPECT_NE(h.reason.find("health_J_factor"), std::string::npos) << h.reason;
    ASSERT_TRUE(h.reference_position);
    EXPECT_EQ(*h.reference_position, Vec2(0.8, 0.3));
  }
  // At the band's edges the run keeps its solution; a wider factor admits more.
  Record edge;
  edge.samples[0].min_J_ratio = 0.05;
  edge.samples[0].max_J_ratio = 20.0;
  EXPECT_FALSE(judge_health(edge.samples, edge.errors, HealthRules{}).lost);
  Record wide;
  wide.samples[0].min_J_ratio = 0.02;
  EXPECT_TRUE(judge_health(wide.samples, wide.errors, HealthRules{}).lost);
  EXPECT_FALSE(judge_health(wide.samples, wide.errors, HealthRules{60.0, 1.0, true}).lost);
  // Without an exact motion the message says J_exact was taken as 1.
  EXPECT_NE(judge_health(wide.samples, wide.errors, HealthRules{20.0, 1.0, false}).reason.find("taken as 1"),
            std::string::npos);
}

TEST(Health, AnErrorNormThatIsNotANumberIsLost) {
  Record r;
  r.errors.columns[0].second[2] = kNaN;
  const auto h = judge_health(r.samples, r.errors, HealthRules{});
  ASSERT_TRUE(h.lost);
  EXPECT_DOUBLE_EQ(h.time, 0.3);
  EXPECT_NE(h.reason.find("L1_line is not a number"), std::string::npos) << h.reason;
  // A norm relative to the exact signal is 0 / 0 where that signal vanishes.
  Record relative;
  relative.errors.add_column("particle_relative_L2_integrated") = {0.1, 0.1, kNaN};
  relative.errors.add_column("error_axial_stretch") = {kNaN, 0.01, 0.01};
  EXPECT_FALSE(judge_health(relative.samples, relative.errors, HealthRules{}).lost);
}

TEST(Health, AnErrorLargerThanTheWholeMotionIsLost) {
  Record r;
  r.errors.columns[1].second[2] = 0.29;  // below the largest exact displacement, 0.3 at t = 0.2
  EXPECT_FALSE(judge_health(r.samples, r.errors, HealthRules{}).lost);
  r.errors.columns[1].second[2] = 0.31;
  const auto h = judge_health(r.samples, r.errors, HealthRules{});
  ASSERT_TRUE(h.lost);
  EXPECT_DOUBLE_EQ(h.time, 0.3);
  EXPECT_NE(h.reason.find("particle_L2 = 0.31 m exceeds"), std::string::npos) << h.reason;
  // A motion larger between the output times (a vibration read at whole
  // periods) counts as well.
  EXPECT_FALSE(judge_health(r.samples, r.errors, HealthRules{}, 0.5).lost);
}

TEST(Health, EnergyLostBeyondItsFactorIsLost) {
  Record r;
  r.samples[0].energy_created = -10.0;  // exactly the scale: within a factor of 1
  EXPECT_FALSE(judge_health(r.samples, r.errors, HealthRules{}).lost);
  r.samples[1].energy_created = -10.5;
  const auto h = judge_health(r.samples, r.errors, HealthRules{});
  ASSERT_TRUE(h.lost);
  EXPECT_DOUBLE_EQ(h.time, 0.2);
  EXPECT_NE(h.reason.find("lost 10.5 J"), std::string::npos) << h.reason;
  EXPECT_FALSE(judge_health(r.samples, r.errors, HealthRules{20.0, 2.0, true}).lost);
}

// Through the binary: the ring on 32 cells keeps J within 1 % of the exact
// J = 1 only to its first output time; with the band set that narrow its run
// reaches the end time and is written "lost", with the rule, time and place.
TEST(Health, MpmvvRunWritesALostRunAsLost) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "mpmvv-health-test";
  fs::create_directories(dir);
  auto run = [&](const std::string& name, const std::string& args) {
    const fs::path out = dir / name;
    fs::remove(out);
    const std::string command = std::string(MPMVV_BINARY) + " run " + MPMVV_SOURCE_DIR +
                                "/suites/scenes/ring.toml -q -t 1 --set cells=32 --set end_time=0.25 "
                                "--set output_times=[0.01,0.1] " + args + " -o " + out.string() + " > /dev/null 2>&1";
    const int status = std::system(command.c_str());
    return std::pair{WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
  };
  const auto [healthy_exit, healthy] = run("healthy.h5", "");
  ASSERT_EQ(healthy_exit, 0);
  {
    const auto file = mpmvv::h5::File::open_read(healthy.string());
    const auto root = file.root();
    EXPECT_EQ(root.attribute_string("status"), "completed");
    EXPECT_EQ(root.attribute_string("health"), "healthy");
    EXPECT_TRUE(std::isnan(root.attribute_double("health_time")));
    // The band the narrow run below leaves: J / J_exact at each output time.
    std::vector<hsize_t> dims;
    const auto low = root.open_group("probes").open_group("monitors").read_doubles("min_J_over_exact", &dims);
    const auto high = root.open_group("probes").open_group("monitors").read_doubles("max_J_over_exact", &dims);
    ASSERT_EQ(low.size(), 3u);
    EXPECT_GT(low[0], 0.99);
    EXPECT_LT(high[0], 1.01);
    EXPECT_TRUE(low[1] < 0.99 || high[1] > 1.01) << low[1] << " " << high[1];
  }
  const auto [lost_exit, lost] = run("lost.h5", "--set health_J_factor=1.01");
  EXPECT_EQ(lost_exit, 1);
  const auto file = mpmvv::h5::File::open_read(lost.string());
  const auto root = file.root();
  EXPECT_EQ(root.attribute_string("status"), "lost");
  EXPECT_EQ(root.attribute_string("health"), "solution lost");
  EXPECT_EQ(root.attribute_string("failure_reason"), "solution lost");
  EXPECT_NE(root.attribute_string("failure_detail").find("health_J_factor"), std::string::npos);
  EXPECT_DOUBLE_EQ(root.attribute_double("health_time"), 0.1);
  EXPECT_DOUBLE_EQ(root.attribute_double("time_reached"), 0.25);
  const auto place = root.attribute_doubles("health_reference_position");
  ASSERT_EQ(place.size(), 2u);
  const double R = std::hypot(place[0], place[1]);
  EXPECT_GE(R, 0.75 - 1e-12);
  EXPECT_LE(R, 1.25 + 1e-12);
}
