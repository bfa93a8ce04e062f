#include "body.hpp"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/General_polygon_set_2.h>
#include <CGAL/Gps_circle_segment_traits_2.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <list>
#include <numbers>
#include <stdexcept>

namespace mpmvv::app {

namespace {

using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using Point = Kernel::Point_2;
using Circle = Kernel::Circle_2;
using Traits = CGAL::Gps_circle_segment_traits_2<Kernel>;
using PolygonSet = CGAL::General_polygon_set_2<Traits>;
using Polygon = Traits::General_polygon_2;
using PolygonWithHoles = Traits::General_polygon_with_holes_2;
using Curve = Traits::Curve_2;
using Arc = Traits::X_monotone_curve_2;

// A closed curve (a full circle) cut into x-monotone arcs.
Polygon circle_polygon(const Vec2& centre, double radius) {
  const Kernel::FT r(radius);
  const Curve circle(Circle(Point(centre.x(), centre.y()), r * r));  // counter-clockwise
  std::vector<boost::variant<Traits::Point_2, Arc>> pieces;
  Traits().make_x_monotone_2_object()(circle, std::back_inserter(pieces));
  Polygon p;
  for (const auto& piece : pieces)
    if (const Arc* arc = boost::get<Arc>(&piece)) p.push_back(*arc);
  return p;
}

Polygon straight_polygon(const std::vector<Vec2>& points) {
  if (points.size() < 3) throw std::invalid_argument("a polygon needs three or more points");
  Polygon p;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec2& a = points[i];
    const Vec2& b = points[(i + 1) % points.size()];
    p.push_back(Arc(Point(a.x(), a.y()), Point(b.x(), b.y())));
  }
  return p;
}

double value(const Traits::Point_2& p, int axis) { return CGAL::to_double(axis == 0 ? p.x() : p.y()); }

// theta - sin(theta) for 0 <= theta <= pi without the cancellation of the
// direct form at small angles (series to theta^11 below 0.1: error < 1e-17 relative).
double angle_minus_sine(double theta) {
  if (theta >= 0.1) return theta - std::sin(theta);
  const double t2 = theta * theta;
  return theta * t2 / 6.0 * (1.0 - t2 / 20.0 * (1.0 - t2 / 42.0 * (1.0 - t2 / 72.0 * (1.0 - t2 / 110.0))));
}

// int dA, int x dA, int y dA of the region the closed boundary pieces enclose
// (outer boundaries counter-clockwise, holes clockwise), by Green's theorem,
// in coordinates about `origin` (the clipping box's corner, so that a piece a
// sub-cell wide loses nothing to the size of its coordinates):
//   A = 1/2 (x dy - y dx), int x dA = 1/2 x^2 dy, int y dA = -1/2 y^2 dx.
// A segment p0 -> p1 contributes the exact polynomials of its end points. An
// arc contributes its chord (the same polynomials) plus the circular segment
// between chord and arc, signed by the arc's orientation about its centre c:
//   A_s = +-(r^2 / 2)(theta - sin theta),   theta = the arc's angle (<= pi: the
//   arcs are x-monotone), from atan2(|cross|, dot), accurate at any angle;
//   its first moment A_s c + (L^2 / 12)(d_y, -d_x), d = p1 - p0, L = |d|
//   (the segment's centroid lies 4 r sin^3(theta/2) / (3 (theta - sin theta))
//   beyond c towards the bulge, and sin(theta/2) = L / 2r).
// No angle is unwrapped, so a vanishing arc (a box corner on the circle)
// contributes nothing rather than a whole circle.
// The circle of an arc p0 -> p1 (in coordinates about `origin`) and the arc's
// signed angle about its centre: |sweep| <= pi (the arcs are x-monotone),
// from atan2(|cross|, dot), accurate at any angle; its sign is the arc's
// orientation, not the cross product's, which is ambiguous at pi.
struct ArcSweep {
  Vec2 centre;
  double squared_radius;
  double sweep;
};

ArcSweep arc_sweep(const Arc& arc, const Vec2& p0, const Vec2& p1, const Vec2& origin) {
  const Circle circle = arc.supporting_circle();
  const Vec2 c = Vec2(CGAL::to_double(circle.center().x()), CGAL::to_double(circle.center().y())) - origin;
  const Vec2 a = p0 - c, b = p1 - c;
  const double angle = std::atan2(std::abs(a.x() * b.y() - a.y() * b.x()), a.dot(b));
  return {c, CGAL::to_double(circle.squared_radius()), arc.orientation() == CGAL::COUNTERCLOCKWISE ? angle : -angle};
}

template <class Curves>
void add_boundary(const Curves& curves, const Vec2& origin, AreaMoments& m) {
  for (auto it = curves.curves_begin(); it != curves.curves_end(); ++it) {
    const Arc& arc = *it;
    const Vec2 p0 = Vec2(value(arc.source(), 0), value(arc.source(), 1)) - origin;
    const Vec2 p1 = Vec2(value(arc.target(), 0), value(arc.target(), 1)) - origin;
    const double x0 = p0.x(), y0 = p0.y(), x1 = p1.x(), y1 = p1.y();
    m.area += 0.5 * (x0 * y1 - x1 * y0);
    m.moment_x += (y1 - y0) * (x0 * x0 + x0 * x1 + x1 * x1) / 6.0;
    m.moment_y -= (x1 - x0) * (y0 * y0 + y0 * y1 + y1 * y1) / 6.0;
    if (arc.is_linear()) continue;
    const ArcSweep s = arc_sweep(arc, p0, p1, origin);
    const Vec2 c = s.centre, d = p1 - p0;
    const double segment = std::copysign(0.5 * s.squared_radius * angle_minus_sine(std::abs(s.sweep)), s.sweep);
    m.area += segment;
    m.moment_x += segment * c.x() + d.squaredNorm() / 12.0 * d.y();
    m.moment_y += segment * c.y() - d.squaredNorm() / 12.0 * d.x();
  }
}

AreaMoments integrate(const PolygonSet& set, const Vec2& origin) {
  std::list<PolygonWithHoles> pieces;
  set.polygons_with_holes(std::back_inserter(pieces));
  AreaMoments m;
  for (const PolygonWithHoles& p : pieces) {
    add_boundary(p.outer_boundary(), origin, m);
    for (auto h = p.holes_begin(); h != p.holes_end(); ++h) add_boundary(*h, origin, m);
  }
  m.moment_x += m.area * origin.x();
  m.moment_y += m.area * origin.y();
  return m;
}

}  // namespace

// A piece of the boundary in floating point, for the fast tests: a segment
// p0 -> p1, or an arc of the circle (centre, radius) from angle `start` over
// the signed angle `sweep`.
struct Piece {
  bool linear;
  Vec2 p0, p1;
  Vec2 centre;
  double radius = 0.0, start = 0.0, sweep = 0.0;
  Vec2 lower, upper;  // bounding box

  // Whether the angle lies on the arc.
  bool on_arc(double angle) const {
    const double two_pi = 2.0 * std::numbers::pi;
    double from = sweep >= 0.0 ? start : start + sweep;
    double offset = std::fmod(angle - from, two_pi);
    if (offset < 0.0) offset += two_pi;
    return offset <= std::abs(sweep);
  }
};

struct Body::Impl {
  PolygonSet set;
  std::vector<Piece> pieces;

  explicit Impl(PolygonSet s) : set(std::move(s)) {
    std::list<PolygonWithHoles> polygons;
    set.polygons_with_holes(std::back_inserter(polygons));
    auto add = [this](const Polygon& p) {
      for (auto it = p.curves_begin(); it != p.curves_end(); ++it) {
        const Arc& arc = *it;
        Piece piece;
        piece.linear = arc.is_linear();
        piece.p0 = Vec2(value(arc.source(), 0), value(arc.source(), 1));
        piece.p1 = Vec2(value(arc.target(), 0), value(arc.target(), 1));
        const CGAL::Bbox_2 b = arc.bbox();
        piece.lower = Vec2(b.xmin(), b.ymin());
        piece.upper = Vec2(b.xmax(), b.ymax());
        if (!piece.linear) {
          const Circle c = arc.supporting_circle();
          piece.centre = Vec2(CGAL::to_double(c.center().x()), CGAL::to_double(c.center().y()));
          piece.radius = std::sqrt(CGAL::to_double(c.squared_radius()));
          piece.start = std::atan2(piece.p0.y() - piece.centre.y(), piece.p0.x() - piece.centre.x());
          double end = std::atan2(piece.p1.y() - piece.centre.y(), piece.p1.x() - piece.centre.x());
          const double two_pi = 2.0 * std::numbers::pi;
          if (arc.orientation() == CGAL::COUNTERCLOCKWISE) {
            while (end <= piece.start) end += two_pi;
          } else {
            while (end >= piece.start) end -= two_pi;
          }
          piece.sweep = end - piece.start;
        }
        pieces.push_back(piece);
      }
    };
    for (const PolygonWithHoles& p : polygons) {
      add(p.outer_boundary());
      for (auto h = p.holes_begin(); h != p.holes_end(); ++h) add(*h);
    }
  }
};

Body Body::rectangle(const Vec2& lower, const Vec2& upper) {
  if (!(upper.x() > lower.x() && upper.y() > lower.y())) throw std::invalid_argument("an empty rectangle");
  return polygon({lower, Vec2(upper.x(), lower.y()), upper, Vec2(lower.x(), upper.y())});
}

Body Body::disk(const Vec2& centre, double radius) {
  if (!(radius > 0.0)) throw std::invalid_argument("a disk needs a positive radius");
  PolygonSet set;
  set.insert(circle_polygon(centre, radius));
  return Body(std::make_shared<const Impl>(std::move(set)));
}

Body Body::annulus(const Vec2& centre, double inner_radius, double outer_radius) {
  if (!(outer_radius > inner_radius && inner_radius > 0.0)) throw std::invalid_argument("an annulus needs 0 < R_i < R_o");
  return disk(centre, outer_radius).minus(disk(centre, inner_radius));
}

Body Body::polygon(const std::vector<Vec2>& outer, const std::vector<std::vector<Vec2>>& holes) {
  PolygonSet set;
  Polygon boundary = straight_polygon(outer);
  if (boundary.orientation() != CGAL::COUNTERCLOCKWISE) boundary.reverse_orientation();
  set.insert(boundary);
  for (const auto& h : holes) {
    Polygon hole = straight_polygon(h);
    if (hole.orientation() != CGAL::COUNTERCLOCKWISE) hole.reverse_orientation();
    set.difference(hole);
  }
  return Body(std::make_shared<const Impl>(std::move(set)));
}

Body Body::minus(const Body& other) const {
  PolygonSet set = impl_->set;
  set.difference(other.impl_->set);
  return Body(std::make_shared<const Impl>(std::move(set)));
}

Body Body::plus(const Body& other) const {
  PolygonSet set = impl_->set;
  set.join(other.impl_->set);
  return Body(std::make_shared<const Impl>(std::move(set)));
}

// The crossing number of a ray from x in a direction no boundary of the
// scenes is aligned with: odd inside. Meant for points away from the boundary
// (the centres of boxes it does not meet); a point on the boundary may go either way.
bool Body::contains(const Vec2& x) const {
  const Vec2 d(std::cos(0.1234567), std::sin(0.1234567));
  int crossings = 0;
  for (const Piece& p : impl_->pieces) {
    if (p.linear) {
      // x + t d = p0 + s (p1 - p0), t > 0, 0 <= s < 1.
      const Vec2 e = p.p1 - p.p0;
      const double det = d.x() * (-e.y()) - d.y() * (-e.x());
      if (det == 0.0) continue;
      const Vec2 w = p.p0 - x;
      const double t = (w.x() * (-e.y()) - w.y() * (-e.x())) / det;
      const double s = (d.x() * w.y() - d.y() * w.x()) / det;
      crossings += t > 0.0 && s >= 0.0 && s < 1.0;
    } else {
      // |x + t d - c|^2 = r^2.
      const Vec2 w = x - p.centre;
      const double b = w.dot(d), c = w.squaredNorm() - p.radius * p.radius;
      const double disc = b * b - c;
      if (disc <= 0.0) continue;
      for (const double t : {-b - std::sqrt(disc), -b + std::sqrt(disc)}) {
        if (!(t > 0.0)) continue;
        const Vec2 q = w + t * d;
        crossings += p.on_arc(std::atan2(q.y(), q.x()));
      }
    }
  }
  return crossings % 2 == 1;
}

// A segment meets the box when their bounding boxes overlap and the box's
// corners do not all lie on one side of its line; a circle cuts the box only
// when its radius lies between the box's nearest and farthest distances from
// the centre. Conservative: a box that passes may still be clear.
bool Body::boundary_may_meet(const Vec2& lower, const Vec2& upper) const {
  const Vec2 corners[4] = {lower, Vec2(upper.x(), lower.y()), upper, Vec2(lower.x(), upper.y())};
  for (const Piece& p : impl_->pieces) {
    if (p.upper.x() < lower.x() || p.lower.x() > upper.x() || p.upper.y() < lower.y() || p.lower.y() > upper.y())
      continue;
    if (p.linear) {
      const Vec2 e = p.p1 - p.p0;
      int positive = 0, negative = 0;
      for (const Vec2& q : corners) {
        const double side = e.x() * (q.y() - p.p0.y()) - e.y() * (q.x() - p.p0.x());
        positive += side >= 0.0;
        negative += side <= 0.0;
      }
      if (positive > 0 && negative > 0) return true;
    } else {
      const Vec2 nearest(std::clamp(p.centre.x(), lower.x(), upper.x()), std::clamp(p.centre.y(), lower.y(), upper.y()));
      double farthest = 0.0;
      for (const Vec2& q : corners) farthest = std::max(farthest, (q - p.centre).norm());
      if ((nearest - p.centre).norm() <= p.radius && p.radius <= farthest) return true;
    }
  }
  return false;
}

AreaMoments Body::clip(const Vec2& lower, const Vec2& upper) const {
  PolygonSet set = impl_->set;
  Polygon box = straight_polygon({lower, Vec2(upper.x(), lower.y()), upper, Vec2(lower.x(), upper.y())});
  set.intersection(box);
  return integrate(set, lower);
}

namespace {

// The boundary curves as points, each arc as chords of at most `max_chord`
// (the sweep taken about the arc's centre, signed by its orientation).
template <class Curves>
void append_outline(const Curves& curves, double max_chord, std::vector<Vec2>& out) {
  for (auto it = curves.curves_begin(); it != curves.curves_end(); ++it) {
    const Arc& arc = *it;
    const Vec2 p0(value(arc.source(), 0), value(arc.source(), 1));
    const Vec2 p1(value(arc.target(), 0), value(arc.target(), 1));
    out.push_back(p0);
    if (arc.is_linear()) continue;
    const ArcSweep s = arc_sweep(arc, p0, p1, Vec2::Zero());
    const Vec2 c = s.centre, a = p0 - c;
    const double r = std::sqrt(s.squared_radius), sweep = s.sweep;
    const int chords = std::max(1, int(std::ceil(std::abs(sweep) * r / max_chord)));
    const double start = std::atan2(a.y(), a.x());
    for (int k = 1; k < chords; ++k) {
      const double angle = start + sweep * k / chords;
      out.push_back(c + r * Vec2(std::cos(angle), std::sin(angle)));
    }
  }
}

}  // namespace

void append_ring(std::vector<Vec2>& chain, const std::vector<Vec2>& ring) {
  if (ring.empty()) return;
  const bool bridged = !chain.empty();
  if (bridged) chain.push_back(chain.front());
  chain.insert(chain.end(), ring.begin(), ring.end());
  if (bridged) chain.push_back(ring.front());
}

std::vector<Vec2> Body::clip_outline(const Vec2& lower, const Vec2& upper, double max_chord) const {
  if (!(max_chord > 0.0)) throw std::invalid_argument("an outline needs a positive chord length");
  PolygonSet set = impl_->set;
  set.intersection(straight_polygon({lower, Vec2(upper.x(), lower.y()), upper, Vec2(lower.x(), upper.y())}));
  std::list<PolygonWithHoles> pieces;
  set.polygons_with_holes(std::back_inserter(pieces));
  std::vector<Vec2> outline;
  auto add_ring = [&](const auto& ring) {
    std::vector<Vec2> points;
    append_outline(ring, max_chord, points);
    append_ring(outline, points);
  };
  for (const PolygonWithHoles& p : pieces) {
    add_ring(p.outer_boundary());
    for (auto h = p.holes_begin(); h != p.holes_end(); ++h) add_ring(*h);
  }
  return outline;
}

AreaMoments Body::whole() const { return integrate(impl_->set, Vec2::Zero()); }

}  // namespace mpmvv::app
