// The manufactured problems run end to end through their scenes
// (find_scene_type(name)->build(config), run): the L1 error of eq. 3.1
// (000_1dbcb8acb6dddab9.txt) on the first probe line at the end time must fall
// under mesh refinement at an observed order inside a measured band.
//
// Orders measured for every method (default keys, cells 8/16/32 unless said;
// the errors of this file's runs, mass-weighted tracers):
//   axis-aligned, t = 0.02 (one period), L1_line_y_mid:
//     cpdi    4.888e-3 1.162e-3 2.903e-4          orders 2.07 2.00 (1.99 on 32/64)
//     gimp    16/32/64: 1.527e-3 5.129e-4 2.722e-4  orders 1.57 0.91 (1.83 on 8/16)
//     linear  8.385e-3 4.616e-3 5.272e-3          orders 0.86 -0.19: no convergence
//   rz-cylinder hollow, t = 0.25 (a quarter period), L1_line_z_quarter:
//     cpdi    4.480e-3 1.168e-3 2.753e-4          orders 1.94 2.08 (2.12 on 32/64)
//     gimp    4.099e-3 9.817e-4 2.504e-4          orders 2.06 1.97 (1.99 on 32/64)
//     linear  16/32/64: 1.127e-3 4.450e-4 4.119e-4  orders 1.34 0.11
//   rz-cylinder hollow, t = 1.0 (the full period):
//     cpdi    7.362e-3 1.623e-3 4.098e-4          orders 2.18 1.99 (2.03 on 32/64)
//     gimp    5.532e-3 2.291e-3 3.222e-3          orders 1.27 -0.49 (-1.15 on 32/64):
//             the error grows from t = 0.35 on, where the radial stretch reaches
//             0.39..1.61 and uGIMP's fixed-size domains leave gaps and overlaps
//             (at amplitude 0.05 gimp converges: orders 1.77 2.12 2.11 on 8..64)
//     linear  9.551e-3 on 8 cells, then a NaN particle stops the run on 16
//             (inner rim, x = (0.2489, 0.0474)) and on 32 (outer rim)
//   rz-cylinder solid (inner_radius = 0), t = 0.25:
//     cpdi    6.028e-4 1.795e-4 4.955e-5          orders 1.75 1.86 (1.90 on 32/64)
//     gimp    5.906e-4 1.705e-4 4.616e-5          orders 1.79 1.88 (1.90 on 32/64)
//     linear  16/32/64: 1.786e-4 6.203e-5 5.661e-5  orders 1.53 0.13
// The full period of the solid cylinder ends where the exact displacement is
// zero (g(1) = 0), and its orders are irregular there (cpdi 2.57 2.26 2.18).
// Every converging case has pairwise orders in [1.75, 2.18] and overall
// orders in [1.80, 2.08]. Band: overall order in [1.7, 2.3], each pairwise
// order in [1.4, 2.6]. The cases that do not converge (linear MPM everywhere:
// the cell-crossing error; uGIMP on the axis-aligned problem and the full
// period of the hollow cylinder: domains that do not follow F under large
// stretch) are limitations of the methods as written, with the numbers above;
// they are not asserted.
#include <gtest/gtest.h>

#include "support.hpp"

#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>
#include <vector>

#include "tools/app/scene/scene.hpp"

namespace {

std::string scientific(double x) { return mpmvv::testing::scientific(x, 4); }

using mpmvv::app::Config;
using mpmvv::app::ErrorTable;

// One problem run on three meshes that halve h, and the method that runs it.
struct ConvergenceCase {
  const char* label;
  const char* scene;
  const char* column;  // "L1_" + the first probe line's name
  std::vector<int> cells;
  std::vector<std::string> overrides;
  const char* method;
};

void PrintTo(const ConvergenceCase& c, std::ostream* out) { *out << c.label << "_" << c.method; }

std::string name_of(const ConvergenceCase& c) { return std::string(c.label) + "_" + c.method; }

// L1 of the case's column at the end time, or NaN when the run stopped early
// (the failure is reported).
double end_error(const ConvergenceCase& c, int cells) {
  const mpmvv::app::SceneType* type = mpmvv::app::find_scene_type(c.scene);
  if (!type) throw std::runtime_error(std::string("no scene ") + c.scene);
  Config config(c.scene, type->keys());
  for (const std::string& o : c.overrides) config.set_from_text(o);
  config.set_from_text(std::string("method=") + c.method);
  config.set_from_text("cells=" + std::to_string(cells));
  auto run = type->build(config);
  const mpmvv::RunOutcome outcome = run->run({});
  EXPECT_TRUE(outcome.completed) << name_of(c) << " cells " << cells << ": " << outcome.failure_reason << " "
                                 << outcome.failure_detail;
  const std::vector<double>& column = run->errors().column(c.column);
  if (!outcome.completed || column.empty()) return std::nan("");
  return column.back();
}

class MmsConvergence : public ::testing::TestWithParam<ConvergenceCase> {};

// The L1 error falls at an observed order inside the band (see the top of the
// file for the measurements behind it).
TEST_P(MmsConvergence, L1FallsAtSecondOrder) {
  const ConvergenceCase& c = GetParam();
  std::vector<double> l1;
  for (int cells : c.cells) l1.push_back(end_error(c, cells));
  const double first = std::log2(l1[0] / l1[1]);
  const double second = std::log2(l1[1] / l1[2]);
  const double overall = 0.5 * std::log2(l1[0] / l1[2]);
  RecordProperty("L1", scientific(l1[0]) + " " + scientific(l1[1]) + " " + scientific(l1[2]));
  RecordProperty("orders", scientific(first) + " " + scientific(second) + " overall " + scientific(overall));
  const std::string values = " L1 " + scientific(l1[0]) + " " + scientific(l1[1]) + " " + scientific(l1[2]);
  EXPECT_GE(first, 1.4) << name_of(c) << values;
  EXPECT_LE(first, 2.6) << name_of(c) << values;
  EXPECT_GE(second, 1.4) << name_of(c) << values;
  EXPECT_LE(second, 2.6) << name_of(c) << values;
  EXPECT_GE(overall, 1.7) << name_of(c) << values;
  EXPECT_LE(overall, 2.3) << name_of(c) << values;
}

const std::vector<std::string> kAxisAligned = {"end_time=0.02", "output_times=0.02"};
const std::vector<std::string> kHollowQuarter = {"end_time=0.25", "output_times=0.25"};
const std::vector<std::string> kHollowPeriod = {"end_time=1.0", "output_times=1.0"};
const std::vector<std::string> kSolidQuarter = {"inner_radius=0", "end_time=0.25", "output_times=0.25"};
const std::vector<int> kCoarse = {8, 16, 32};

INSTANTIATE_TEST_SUITE_P(
    Converging, MmsConvergence,
    ::testing::Values(
        ConvergenceCase{"axis_aligned", "axis-aligned", "L1_line_y_mid", kCoarse, kAxisAligned, "cpdi"},
        ConvergenceCase{"rz_hollow_quarter", "rz-cylinder", "L1_line_z_quarter", kCoarse, kHollowQuarter, "cpdi"},
        ConvergenceCase{"rz_hollow_quarter", "rz-cylinder", "L1_line_z_quarter", kCoarse, kHollowQuarter, "gimp"},
        ConvergenceCase{"rz_hollow_period", "rz-cylinder", "L1_line_z_quarter", kCoarse, kHollowPeriod, "cpdi"},
        ConvergenceCase{"rz_solid_quarter", "rz-cylinder", "L1_line_z_quarter", kCoarse, kSolidQuarter, "cpdi"},
        ConvergenceCase{"rz_solid_quarter", "rz-cylinder", "L1_line_z_quarter", kCoarse, kSolidQuarter, "gimp"}),
    [](const auto& info) { return name_of(info.param); });

}  // namespace
