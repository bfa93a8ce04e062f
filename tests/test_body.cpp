// Exact body geometry (tools/app/scene/body.hpp): areas and first moments of whole
// bodies and of their parts in boxes, from CGAL's exact Boolean intersection
// and Green's theorem; the inside test and the cut-box test the seeding uses.
#include <gtest/gtest.h>

#ifdef MPMVV_HAVE_CGAL

#include <cmath>
#include <numbers>
#include <random>

#include "tools/app/scene/body.hpp"
#include "tools/app/scene/scene.hpp"

namespace {

using mpmvv::Vec2;
using mpmvv::app::AreaMoments;
using mpmvv::app::Body;
using std::numbers::pi;

// Round-off of sums of order one: a few 1e-16 per piece.
constexpr double kRoundOff = 1e-13;

}  // namespace

// Whole bodies: areas and centroids of a disk, a ring, a rectangle and a
// plate with a hole equal their closed forms.
TEST(Body, WholeAreasAndCentroidsAreExact) {
  const AreaMoments disk = Body::disk(Vec2(0.3, -0.2), 0.5).whole();
  EXPECT_NEAR(disk.area, pi * 0.25, kRoundOff);
  EXPECT_NEAR(disk.centroid().x(), 0.3, kRoundOff);
  EXPECT_NEAR(disk.centroid().y(), -0.2, kRoundOff);
  EXPECT_NEAR(Body::annulus(Vec2::Zero(), 0.75, 1.25).whole().area, pi, kRoundOff);
  const AreaMoments plate = Body::polygon({Vec2(0, 0), Vec2(2, 0), Vec2(2, 1), Vec2(0, 1)},
                                         {{Vec2(0.5, 0.25), Vec2(1, 0.25), Vec2(1, 0.75), Vec2(0.5, 0.75)}})
                                .whole();
  EXPECT_NEAR(plate.area, 1.75, kRoundOff);
  // Centroid of the plate with its hole: (2 * 1 - 0.25 * 0.75) / 1.75.
  EXPECT_NEAR(plate.centroid().x(), (2.0 * 1.0 - 0.25 * 0.75) / 1.75, kRoundOff);
  EXPECT_NEAR(Body::rectangle(Vec2(0.25, 0), Vec2(1, 1)).whole().area, 0.75, kRoundOff);
}

// Parts in boxes: a quarter disk has centroid 4 r / (3 pi) on each axis; a
// half ring has its centroid at 4 (R_o^3 - R_i^3) / (3 pi (R_o^2 - R_i^2)).
TEST(Body, ClippedPartsHaveTheirClosedForms) {
  const AreaMoments quarter = Body::disk(Vec2::Zero(), 1.0).clip(Vec2(0, 0), Vec2(2, 2));
  EXPECT_NEAR(quarter.area, pi / 4.0, kRoundOff);
  EXPECT_NEAR(quarter.centroid().x(), 4.0 / (3.0 * pi), kRoundOff);
  const AreaMoments half = Body::annulus(Vec2::Zero(), 0.75, 1.25).clip(Vec2(-2, 0), Vec2(2, 2));
  EXPECT_NEAR(half.centroid().x(), 0.0, kRoundOff);
  EXPECT_NEAR(half.centroid().y(), 4.0 * (1.25 * 1.25 * 1.25 - 0.75 * 0.75 * 0.75) / (3.0 * pi * (1.25 * 1.25 - 0.75 * 0.75)),
              kRoundOff);
  // A circular segment x > 1/2 of the unit disk.
  EXPECT_NEAR(Body::disk(Vec2::Zero(), 1.0).clip(Vec2(0.5, -2), Vec2(2, 2)).area,
              std::acos(0.5) - 0.5 * std::sqrt(0.75), kRoundOff);
}

// Cutting a body into grid cells, as the seeding does (the cut-box test, the
// exact clip where it passes, the inside test elsewhere), gives back its area
// and first moments: the particles of a ring hold exactly its volume.
TEST(Body, CellsAddUpToTheWhole) {
  for (const Body& body : {Body::annulus(Vec2::Zero(), 0.75, 1.25), Body::disk(Vec2(0.1, 0.05), 0.9),
                           Body::rectangle(Vec2(-0.33, -0.71), Vec2(1.07, 0.2))}) {
    const AreaMoments whole = body.whole();
    const int n = 48;
    const double h = 3.0 / n;
    AreaMoments sum;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Vec2 lo(-1.5 + i * h, -1.5 + j * h), hi = lo + Vec2(h, h), centre = lo + 0.5 * Vec2(h, h);
        AreaMoments part;
        if (body.boundary_may_meet(lo, hi)) part = body.clip(lo, hi);
        else if (body.contains(centre)) part = {h * h, h * h * centre.x(), h * h * centre.y()};
        sum.area += part.area;
        sum.moment_x += part.moment_x;
        sum.moment_y += part.moment_y;
      }
    EXPECT_NEAR(sum.area, whole.area, kRoundOff);
    EXPECT_NEAR(sum.moment_x, whole.moment_x, kRoundOff);
    EXPECT_NEAR(sum.moment_y, whole.moment_y, kRoundOff);
  }
}

// The cut-box test has no false negatives: every random box the boundary
// really cuts (its clipped area strictly between 0 and the box's area)
// passes it; and the inside test agrees with the clip for boxes that pass no boundary.
TEST(Body, CutTestMissesNoCutBoxAndInsideTestAgreesWithClip) {
  const Body body = Body::annulus(Vec2::Zero(), 0.75, 1.25).plus(Body::rectangle(Vec2(1.0, -0.1), Vec2(1.4, 0.1)));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.5, 1.5), size(0.01, 0.3);
  int cut = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vec2 lo(u(rng), u(rng));
    const double s = size(rng);
    const Vec2 hi = lo + Vec2(s, s);
    const double area = body.clip(lo, hi).area;
    const bool really_cut = area > 1e-12 * s * s && area < (1.0 - 1e-12) * s * s;
    if (really_cut) {
      ++cut;
      EXPECT_TRUE(body.boundary_may_meet(lo, hi)) << lo.transpose() << " size " << s;
    } else if (!body.boundary_may_meet(lo, hi)) {
      EXPECT_EQ(body.contains(lo + 0.5 * Vec2(s, s)), area > 0.5 * s * s) << lo.transpose() << " size " << s;
    }
  }
  EXPECT_GT(cut, 200);  // the sample does exercise cut boxes
}

// The ring scene seeded exactly holds the ring's volume pi to round-off.
TEST(Body, RingSceneHoldsExactlyTheRingsVolume) {
  mpmvv::app::Config config("ring", mpmvv::app::find_scene_type("ring")->keys());
  for (const char* o : {"cells=48", "end_time=0.01", "output_times=0.01", "seeding=exact"}) config.set_from_text(o);
  auto scene = mpmvv::app::find_scene_type("ring")->build(config);
  ASSERT_TRUE(scene->run({}).completed);
  EXPECT_NEAR(scene->particle_volume(), pi, kRoundOff);
  EXPECT_NEAR(scene->body_volume(), pi, kRoundOff);
}

// Boxes whose edges or corners touch the circle: the Sandia meshes of 300
// and 600 cells put grid lines on the ring's rims (x = 1.25 = 125 h), where a
// clip holds vanishing arcs. Every piece must lie in its box and the pieces
// must add up to the ring: a vanishing arc once counted as a whole circle
// (area 4.9 in a box of 2.5e-5) and a sliver's centroid landed outside the grid.
TEST(Body, BoxesTouchingTheCircleClipCorrectly) {
  const Body ring = Body::annulus(Vec2::Zero(), 0.75, 1.25);
  for (int cells : {300, 600}) {
    const double s = 3.0 / cells / 2.0;  // 2 particles per direction
    const int n = 2 * cells;
    long double area = 0.0;  // 1.4 million terms: a double sum would drift by 3e-11
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Vec2 lo = Vec2(-1.5, -1.5) + s * Vec2(i, j), hi = lo + Vec2(s, s);
        if (!ring.boundary_may_meet(lo, hi)) {
          if (ring.contains(lo + 0.5 * Vec2(s, s))) area += s * s;
          continue;
        }
        const AreaMoments m = ring.clip(lo, hi);
        ASSERT_GE(m.area, -1e-15 * s * s) << cells << " cells, box at " << lo.transpose();
        ASSERT_LE(m.area, (1.0 + 1e-12) * s * s) << cells << " cells, box at " << lo.transpose();
        area += m.area;
        if (m.area < 1e-9 * s * s) continue;
        const Vec2 c = m.centroid();
        EXPECT_TRUE(c.x() >= lo.x() - 1e-9 * s && c.x() <= hi.x() + 1e-9 * s && c.y() >= lo.y() - 1e-9 * s &&
                    c.y() <= hi.y() + 1e-9 * s)
            << cells << " cells: centroid " << c.transpose() << " outside its box at " << lo.transpose();
      }
    EXPECT_NEAR(double(area), pi, 1e-12) << cells << " cells";
  }
}

// Outlines of clipped parts (exact CPDI domains): a box the ring's inner
// circle cuts, a box holding the whole hole (one piece with a hole, on a
// bridge) and a box the ring crosses twice (two pieces, on a bridge). The
// outline's own Green's-theorem area equals the exact clipped area less the
// circular segments its chords leave out, each below L^3 / (12 R).
TEST(Body, OutlinesOfClippedPartsHoldTheirArea) {
  const Body ring = Body::annulus(Vec2::Zero(), 0.4, 0.6);
  const double chord = 0.01;
  struct Box {
    Vec2 lower, upper;
  };
  for (const Box& box : {Box{Vec2(0.38, -0.03), Vec2(0.43, 0.02)}, Box{Vec2(-0.7, -0.7), Vec2(0.7, 0.7)},
                         Box{Vec2(-0.7, -0.05), Vec2(0.7, 0.05)}, Box{Vec2(0.45, 0.1), Vec2(0.5, 0.15)}}) {
    const std::vector<Vec2> outline = ring.clip_outline(box.lower, box.upper, chord);
    ASSERT_GE(outline.size(), 3u);
    double twice_area = 0.0;
    for (std::size_t k = 0; k < outline.size(); ++k) {
      const Vec2& a = outline[k];
      const Vec2& b = outline[(k + 1) % outline.size()];
      twice_area += a.x() * b.y() - b.x() * a.y();
      EXPECT_GE(a.x(), box.lower.x() - 1e-12);
      EXPECT_LE(a.x(), box.upper.x() + 1e-12);
    }
    const double exact = ring.clip(box.lower, box.upper).area;
    const double perimeter = 2.0 * pi * (0.4 + 0.6);
    const double sagitta_bound = perimeter / chord * chord * chord * chord / (12.0 * 0.4);
    EXPECT_NEAR(0.5 * twice_area, exact, sagitta_bound) << "box from (" << box.lower.x() << ", " << box.lower.y() << ")";
    EXPECT_GT(0.5 * twice_area, 0.0);
  }
  EXPECT_THROW(ring.clip_outline(Vec2(0.38, -0.03), Vec2(0.43, 0.02), 0.0), std::invalid_argument);
}

#endif  // MPMVV_HAVE_CGAL
