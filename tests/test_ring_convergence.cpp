// The ring MMS run end to end through its scene: the error of eq. 3.1 must fall
// under mesh refinement at an observed order inside a measured band.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "tools/app/scene/scene.hpp"

namespace {

using mpmvv::app::Config;
using mpmvv::app::ErrorTable;

ErrorTable run_ring(const std::vector<std::string>& overrides) {
  Config config("ring", mpmvv::app::find_scene_type("ring")->keys());
  for (const std::string& o : overrides) config.set_from_text(o);
  auto scene = mpmvv::app::find_scene_type("ring")->build(config);
  const mpmvv::RunOutcome outcome = scene->run({});
  EXPECT_TRUE(outcome.completed) << outcome.failure_reason << " " << outcome.failure_detail;
  return scene->errors();
}

class RingConvergence : public ::testing::TestWithParam<const char*> {};

}  // namespace

// L1 on Theta = 0 at t = 0.25 s, A = 0.5, cosine time function, 2 particles per
// cell per direction, cfl 0.3, exact seeding (clipped volumes), cells 32 -> 64
// -> 128 (h halves each time). Measured (linear, gimp, cpdi): pairwise orders
// 1.86, 1.86, 1.80 then 2.04, 2.01, 1.97; overall 1.95, 1.94, 1.89. (With
// centre seeding the pairwise orders alternated 1.5, 2.3 because the particle
// lattice met the rims differently at each h: a build without CGAL, which
// seeds that way, measures 1.56-1.80 then 2.30-2.36.) Band: overall order in
// [1.7, 2.1], each pairwise order in [1.5, 2.3] (without CGAL [1.4, 2.5]).
TEST_P(RingConvergence, L1FallsAtObservedOrderInBand) {
  const std::string method = GetParam();
  std::vector<double> l1;
  for (int cells : {32, 64, 128}) {
    const ErrorTable e = run_ring({"method=" + method, "cells=" + std::to_string(cells), "end_time=0.25",
                                   "output_times=0.25", "amplitude=0.5"});
    l1.push_back(e.column("L1_theta0").back());
  }
  const double first = std::log2(l1[0] / l1[1]);
  const double second = std::log2(l1[1] / l1[2]);
  const double overall = 0.5 * std::log2(l1[0] / l1[2]);
  RecordProperty("orders", std::to_string(first) + " " + std::to_string(second));
#ifdef MPMVV_HAVE_CGAL
  const double low = 1.5, high = 2.3;
#else
  const double low = 1.4, high = 2.5;
#endif
  EXPECT_GE(first, low) << method;
  EXPECT_LE(first, high) << method;
  EXPECT_GE(second, low) << method;
  EXPECT_LE(second, high) << method;
  EXPECT_GE(overall, 1.7) << method << " L1 " << l1[0] << " " << l1[1] << " " << l1[2];
  EXPECT_LE(overall, 2.1) << method << " L1 " << l1[0] << " " << l1[1] << " " << l1[2];
}

INSTANTIATE_TEST_SUITE_P(Methods, RingConvergence, ::testing::Values("linear", "gimp", "cpdi"));
