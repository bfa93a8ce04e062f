// How the particles' domains cover the body as it moves: the partition of
// unity of the particle basis (the characteristic functions of the domains
// summed over the particles) and the holes where that sum falls below one.
// 003_0440bbfcfbc3a876.txt ("Holey particle basis functions for 2D CPDI")
// shows CPDI's domains losing their overlapping support under extreme 2D
// deformation, which lets material interpenetrate; the distortion monitor
// (solver/monitors.hpp) sees a domain's shape, not the gaps between domains.
//
// The body is sampled by a square lattice of reference points, `samples`
// per particle spacing along each axis (each jittered within its square of
// the lattice, coverage.cpp: jitter), over the box of the domains at the
// start; the points that some domain covers then are the body's material as
// the method tiles it (a curved side's stair of squares included, so only
// what opens later counts), and the first domain found holding a point is
// its owner. At each output time every such point X is carried to
//   x = x_exact(X, t) + e(X),
// the exact motion shifted by the solution's displacement error e, the
// errors e_q = x_q - x_exact(X_q, t) of the particles interpolated over the
// reference body (coverage.cpp: ErrorField; bilinear on the seeding's rows):
// without the shift a side of the body moved by the error would read as
// material no domain covers (the ring at A = 2 on 64 cells with corner
// domains, which share their corners and leave no gap: 2.5 % of the
// material at t = 0.1 s), and with it the particles' own scatter (a lost
// solution's) moves the points between them as it moves them. x is then
// looked up among the current domains (solver/domain_polygons.hpp); a point
// that no domain contains sits in a hole, counted apart where its owner's
// domain lies at a side of the body (held a point next to one outside it at
// the start): there a domain's side and its centre also part by the error
// in F_p, and corner domains, which leave no gap inside, leave some
// material out. Holes are the 4-connected sets of such points on the
// lattice, each of current area sum d^2 J_exact(X), d the lattice spacing:
// resolved to d (one point is (d / h)^2 cells), so a sliver thinner than d
// is missed or broken up, while the share of the material in holes is an
// area estimate that converges as d shrinks (the ring at A = 2, 64 cells,
// 1 particle per direction, CPDI, t = 0.5 s: 18.6 %, 17.3 %, 17.6 %, 17.7 %,
// 17.8 % of the material with 1, 2, 4, 8, 16 samples).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "mms/exact_solution.hpp"
#include "solver/domain_polygons.hpp"

namespace mpmvv {
class StateArchive;
}

namespace mpmvv::app {

// The domains, bucketed by their bounding boxes, for point queries.
class DomainIndex {
 public:
  explicit DomainIndex(const DomainPolygons& domains);
  static constexpr std::uint32_t kNone = ~std::uint32_t(0);
  // The first domain that contains x, or kNone (crossing number: a
  // turned-over or crossed outline counts by its even-odd rule).
  std::uint32_t holder(const Vec2& x) const;

 private:
  const DomainPolygons* domains_;
  Vec2 low_ = Vec2::Zero();
  double bucket_ = 1.0;
  int nx_ = 0, ny_ = 0;
  std::vector<std::uint32_t> start_, entry_;  // bucket b's domains: entry_[start_[b] .. start_[b + 1])
};

class DomainCoverage {
 public:
  struct Row {
    double time;
    double uncovered_fraction;  // of the sampled material, by reference area, in holes
    double inside_fraction;     // the same, of the points whose owner's domain is away from the body's sides
    double largest_hole_area;   // current area of the largest [m^2 per unit depth; r-z plane in r-z]
  };

  // Lays the lattice over `domains` at the start, spacing `spacing` [m];
  // the particles were seeded `particle_spacing` apart.
  void start(const DomainPolygons& domains, double spacing, double particle_spacing);
  bool on() const { return !owner_.empty(); }
  // The holes at time t among the domains of the particles P, the body
  // carried by `solution` as above.
  void record(double t, const DomainPolygons& domains, const Particles& P, const mms::ExactSolution& solution);

  const std::vector<Row>& rows() const { return rows_; }
  double spacing() const { return spacing_; }
  std::size_t sampled_points() const { return body_points_; }
  // What has been recorded and the lattice, under their restart-file names.
  void persist(StateArchive& a);

 private:
  Vec2 point(std::int64_t i, std::int64_t j) const;  // origin_ + d ((i, j) + jitter)
  Vec2 origin_ = Vec2::Zero();
  double spacing_ = 0.0, particle_spacing_ = 0.0;
  std::int64_t nx_ = 0, ny_ = 0;
  std::vector<std::uint32_t> owner_;  // the point's domain at the start, or DomainIndex::kNone; row by row
  std::vector<std::uint8_t> at_side_;  // per particle: its domain held a point next to one outside the body
  std::size_t body_points_ = 0;
  std::vector<Row> rows_;
};

}  // namespace mpmvv::app
