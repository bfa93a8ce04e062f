// The domain coverage monitor (tools/app/scene/coverage.hpp): on a tiling of
// squares it finds no hole, a missing square is a hole of that square's area,
// a side moved by the motion but not by the domains opens a strip, and a
// displacement error the particles share is not taken for a hole; through
// the binary, convected CPDI on the ring at A = 2 opens holes that corner
// domains, which share their corners, do not, and a method without domains
// writes no coverage.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "run_scene.hpp"
#include "solver/domain_polygons.hpp"
#include "tools/app/scene/coverage.hpp"

namespace {

using mpmvv::DomainPolygons;
using mpmvv::Vec2;
using mpmvv::app::DomainCoverage;

// x = X + (a t X, 0) + shift t: a stretch along x and a translation.
class Stretch final : public mpmvv::mms::ExactSolution {
 public:
  Stretch(double a, Vec2 shift) : a_(a), shift_(shift) {}
  mpmvv::Geometry geometry() const override { return mpmvv::Geometry::plane_strain; }
  double density() const override { return 1.0; }
  Vec2 position(const Vec2& X, double t) const override { return X + Vec2(a_ * t * X.x(), 0.0) + t * shift_; }
  mpmvv::mms::ExactFields fields(const Vec2& X, double t) const override {
    mpmvv::mms::ExactFields f{};
    f.position = position(X, t);
    f.deformation_gradient << 1.0 + a_ * t, 0.0, 0.0, 1.0;
    f.hoop_stretch = 1.0;
    f.J = 1.0 + a_ * t;
    return f;
  }
  Vec2 body_force(const Vec2&, double) const override { return Vec2::Zero(); }
  void body_forces(double, const std::vector<Vec2>& X, std::vector<Vec2>& b) const override {
    b.assign(X.size(), Vec2::Zero());
  }
  mpmvv::mms::ResidualCheck check(const Vec2&, double, double) const override { return {Vec2::Zero(), 0.0}; }

 private:
  double a_;
  Vec2 shift_;
};

// The unit squares [i, i + 1] x [j, j + 1] of an n x n block, but `missing`
// (given as i + n j), each scaled along x by `stretch` and moved by `shift`;
// `P` gets one particle at each square's centre, its reference position the
// unmoved centre.
DomainPolygons squares(int n, std::vector<int> missing, double stretch, Vec2 shift, mpmvv::Particles& P) {
  DomainPolygons d;
  P.position.clear();
  P.reference_position.clear();
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (std::find(missing.begin(), missing.end(), i + n * j) != missing.end()) continue;
      d.first.push_back(d.vertex.size());
      for (const Vec2& c : {Vec2(i, j), Vec2(i + 1, j), Vec2(i + 1, j + 1), Vec2(i, j + 1)})
        d.vertex.push_back(Vec2(stretch * c.x(), c.y()) + shift);
      const Vec2 centre(i + 0.5, j + 0.5);
      P.reference_position.push_back(centre);
      P.position.push_back(Vec2(stretch * centre.x(), centre.y()) + shift);
    }
  d.first.push_back(d.vertex.size());
  return d;
}

TEST(DomainCoverage, ATilingHasNoHoleAndAMissingSquareIsOne) {
  mpmvv::Particles P;
  DomainCoverage coverage;
  coverage.start(squares(4, {}, 1.0, Vec2::Zero(), P), 0.25, 1.0);
  EXPECT_EQ(coverage.sampled_points(), 256u);
  const Stretch still(0.0, Vec2::Zero());
  coverage.record(1.0, squares(4, {}, 1.0, Vec2::Zero(), P), P, still);
  coverage.record(2.0, squares(4, {5}, 1.0, Vec2::Zero(), P), P, still);
  coverage.record(3.0, squares(4, {5, 10}, 1.0, Vec2::Zero(), P), P, still);  // apart (diagonal)
  coverage.record(4.0, squares(4, {5, 6}, 1.0, Vec2::Zero(), P), P, still);   // side by side
  ASSERT_EQ(coverage.rows().size(), 4u);
  EXPECT_EQ(coverage.rows()[0].uncovered_fraction, 0.0);
  EXPECT_EQ(coverage.rows()[0].largest_hole_area, 0.0);
  EXPECT_DOUBLE_EQ(coverage.rows()[1].uncovered_fraction, 1.0 / 16.0);
  EXPECT_DOUBLE_EQ(coverage.rows()[1].largest_hole_area, 1.0);
  EXPECT_DOUBLE_EQ(coverage.rows()[1].inside_fraction, 1.0 / 16.0);  // square 5 is away from the sides
  EXPECT_DOUBLE_EQ(coverage.rows()[2].uncovered_fraction, 2.0 / 16.0);
  EXPECT_DOUBLE_EQ(coverage.rows()[2].largest_hole_area, 1.0);
  EXPECT_DOUBLE_EQ(coverage.rows()[3].largest_hole_area, 2.0);
}

// The motion stretches the block by 1.5 along x while the domains and the
// particles stay: each particle is off by -0.5 X_q along x. Between the
// particles' centres the interpolated error is that linear field, and the
// points land where they started; past the outermost centres it is held at
// their column's error, so a point at offset s from such a centre sits at
// 1.5 s, outside every domain beyond s = 1/3. Two strips of reference width
// 1/6 at the left and right sides, 1/12 of the material, each of current
// area 1.5 * 4/6 = 1, all owned by domains at the sides.
TEST(DomainCoverage, AStretchTheDomainsMissOpensTheSidesAndACommonErrorOpensNothing) {
  mpmvv::Particles P;
  DomainCoverage coverage;
  coverage.start(squares(4, {}, 1.0, Vec2::Zero(), P), 1.0 / 12.0, 1.0);  // 48 x 48 points
  coverage.record(1.0, squares(4, {}, 1.0, Vec2::Zero(), P), P, Stretch(0.5, Vec2::Zero()));
  const DomainCoverage::Row& stretch = coverage.rows().back();
  EXPECT_NEAR(stretch.uncovered_fraction, 1.0 / 12.0, 2.0 / 48.0 / 4.0);
  EXPECT_EQ(stretch.inside_fraction, 0.0);
  EXPECT_NEAR(stretch.largest_hole_area, 1.0, 1.5 * 4.0 / 48.0);
  // Particles and domains moved by (0.3, -0.2); the motion not at all.
  coverage.record(2.0, squares(4, {}, 1.0, Vec2(0.3, -0.2), P), P, Stretch(0.0, Vec2::Zero()));
  EXPECT_EQ(coverage.rows().back().uncovered_fraction, 0.0);
  // The motion and the particles moved by it, the domains with them.
  coverage.record(3.0, squares(4, {}, 1.0, Vec2(0.3, -0.2), P), P, Stretch(0.0, Vec2(0.3, -0.2) / 3.0));
  EXPECT_EQ(coverage.rows().back().uncovered_fraction, 0.0);
}

// A domain gone to NaN contains no point, and the monitor stays finite.
TEST(DomainCoverage, ADomainGoneToNanCoversNothing) {
  mpmvv::Particles P;
  DomainCoverage coverage;
  coverage.start(squares(2, {}, 1.0, Vec2::Zero(), P), 0.5, 1.0);
  DomainPolygons d = squares(2, {}, 1.0, Vec2::Zero(), P);
  for (std::size_t k = d.first[3]; k < d.first[4]; ++k) d.vertex[k] = Vec2::Constant(std::nan(""));
  P.position[3] = Vec2::Constant(std::nan(""));
  coverage.record(1.0, d, P, Stretch(0.0, Vec2::Zero()));
  EXPECT_DOUBLE_EQ(coverage.rows().back().uncovered_fraction, 0.25);
  EXPECT_DOUBLE_EQ(coverage.rows().back().largest_hole_area, 1.0);
}

std::vector<double> coverage_column(const mpmvv::h5::File& f, const std::string& name) {
  return f.root().open_group("probes").open_group("coverage").read_doubles(name);
}

// The ring at A = 2 on 32 cells to t = 0.2 s (measured: convected CPDI
// 6.25 % of the material in holes, 2.34 % away from the sides; corner
// domains 3.48 %, none away from the sides: theirs open where a domain's
// side and its centre part by F's error). Linear MPM has no domains: no
// /probes/coverage.
TEST(DomainCoverage, ConvectedCpdiOpensHolesCornerDomainsDoNot) {
  const std::string ring = "--set cells=32 --set amplitude=2 --set particles_per_direction=1 --set end_time=0.2 "
                           "--set 'output_times=[0.1, 0.2]' --set coverage_samples=2 ";
  const mpmvv::h5::File convected = mpmvv::testing::run_scene("ring.toml", "coverage-cpdi", ring + "--set method=cpdi");
  const mpmvv::h5::File corners = mpmvv::testing::run_scene(
      "ring.toml", "coverage-corners", ring + "--set method=cpdi --set cpdi_domain=corners");
  const std::vector<double> open = coverage_column(convected, "inside_fraction");
  const std::vector<double> shut = coverage_column(corners, "inside_fraction");
  ASSERT_EQ(open.size(), 2u);
  ASSERT_EQ(shut.size(), 2u);
  EXPECT_GT(open[1], 0.015);
  EXPECT_LT(shut[1], 0.005);
  EXPECT_GT(open[1], 10.0 * shut[1]);
  EXPECT_GE(coverage_column(convected, "uncovered_fraction")[1], open[1]);
  const mpmvv::h5::File linear = mpmvv::testing::run_scene("ring.toml", "coverage-linear", ring + "--set method=linear");
  EXPECT_FALSE(linear.root().open_group("probes").has("coverage"));
}

}  // namespace
