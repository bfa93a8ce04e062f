// Exact body geometry (CGAL): a body bounded by line segments and circular
// arcs (rectangles, disks, rings, polygons with holes), and the exact area
// and first moments of its intersection with an axis-aligned box, from the
// regularized Boolean intersection (Gps_circle_segment_traits_2) and Green's
// theorem over the pieces of its boundary. Particles in cells the boundary cuts
// get these clipped volumes, so the total volume of every body is exact.
#pragma once

#include <memory>
#include <vector>

#include "solver/tensor.hpp"

namespace mpmvv::app {

// Integrals over a region: the area and int x dA, int y dA.
struct AreaMoments {
  double area = 0.0;
  double moment_x = 0.0;
  double moment_y = 0.0;
  Vec2 centroid() const { return Vec2(moment_x, moment_y) / area; }
};

// Appends a closed ring of points to a chain of rings (one outline): the ring
// hangs off the chain's first point - back to it (which closes the ring
// before), over to the new ring, round it and closed; the chain's own closing
// edge is the bridge back. Walked both ways, a bridge adds nothing to any
// integral over the region by Green's theorem.
void append_ring(std::vector<Vec2>& chain, const std::vector<Vec2>& ring);

class Body {
 public:
  static Body rectangle(const Vec2& lower, const Vec2& upper);
  static Body disk(const Vec2& centre, double radius);
  static Body annulus(const Vec2& centre, double inner_radius, double outer_radius);
  // Counter-clockwise outer boundary; holes are removed from it.
  static Body polygon(const std::vector<Vec2>& outer, const std::vector<std::vector<Vec2>>& holes = {});

  Body minus(const Body& other) const;
  Body plus(const Body& other) const;

  // Exact predicates: inside or on the boundary.
  bool contains(const Vec2& x) const;
  // Whether the boundary can meet the box (bounding boxes of its pieces; a
  // box it does not meet lies wholly inside or wholly outside).
  bool boundary_may_meet(const Vec2& lower, const Vec2& upper) const;
  // The part of the body inside the box.
  AreaMoments clip(const Vec2& lower, const Vec2& upper) const;
  AreaMoments whole() const;
  // The outline of the part of the body inside the box: one closed chain of
  // points, its arcs cut into chords no longer than `max_chord`; several
  // pieces (or a piece with a hole) are joined by bridges walked both ways,
  // which add nothing to any integral over the region by Green's theorem.
  std::vector<Vec2> clip_outline(const Vec2& lower, const Vec2& upper, double max_chord) const;

 private:
  struct Impl;
  explicit Body(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}
  std::shared_ptr<const Impl> impl_;
};

}  // namespace mpmvv::app
