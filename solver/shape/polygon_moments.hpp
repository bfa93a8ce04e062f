// Moments of a polygon and its clipping against an axis-parallel line, the
// two pieces of the exact integration of a CPDI domain over the cells it
// meets (cpdi_exact.hpp).
#pragma once

#include "../tensor.hpp"

namespace mpmvv {

// int 1, int u, int v, int u v over a polygon, counter-clockwise vertices
// (u_k, v_k): with c_k = u_k v_{k+1} - u_{k+1} v_k,
//   A = (1/2) sum c_k,  int u = (1/6) sum (u_k + u_{k+1}) c_k  (v alike),
//   int u v = (1/24) sum c_k (u_k v_{k+1} + 2 u_k v_k + 2 u_{k+1} v_{k+1} + u_{k+1} v_k).
// With `radial` also the moments an r weight needs (r linear in u):
//   int u^2 = (1/12) sum c_k (u_k^2 + u_k u_{k+1} + u_{k+1}^2),
//   int u^2 v = (1/60) sum c_k (u_k^2 (3 v_k + v_{k+1}) + 2 u_k u_{k+1} (v_k + v_{k+1})
//                               + u_{k+1}^2 (v_k + 3 v_{k+1})).
struct PolygonMoments {
  double area = 0.0, u = 0.0, v = 0.0, uv = 0.0;
  double uu = 0.0, uuv = 0.0;  // radial moments only
};

template <bool radial = false>
inline PolygonMoments polygon_moments(const Vec2* vertex, int count) {
  PolygonMoments m;
  for (int k = 0; k < count; ++k) {
    const Vec2& a = vertex[k];
    const Vec2& b = vertex[k + 1 == count ? 0 : k + 1];
    const double c = a.x() * b.y() - b.x() * a.y();
    m.area += c;
    m.u += (a.x() + b.x()) * c;
    m.v += (a.y() + b.y()) * c;
    m.uv += c * (a.x() * b.y() + 2.0 * a.x() * a.y() + 2.0 * b.x() * b.y() + b.x() * a.y());
    if constexpr (radial) {
      m.uu += c * (a.x() * a.x() + a.x() * b.x() + b.x() * b.x());
      m.uuv += c * (a.x() * a.x() * (3.0 * a.y() + b.y()) + 2.0 * a.x() * b.x() * (a.y() + b.y()) +
                    b.x() * b.x() * (a.y() + 3.0 * b.y()));
    }
  }
  m.area /= 2.0;
  m.u /= 6.0;
  m.v /= 6.0;
  m.uv /= 24.0;
  m.uu /= 12.0;
  m.uuv /= 60.0;
  return m;
}

// The part of a polygon on the side axis-coordinate >= bound (keep_above)
// or <= bound: each edge gives at most two points, and no more than
// `capacity` are written (the callers' buffers hold every realistic outline).
inline int clip_polygon(const Vec2* in, int count, int axis, double bound, bool keep_above, Vec2* out,
                        int capacity) {
  int n = 0;
  for (int k = 0; k < count && n + 2 <= capacity; ++k) {
    const Vec2& a = in[k];
    const Vec2& b = in[k + 1 == count ? 0 : k + 1];
    const double da = keep_above ? a[axis] - bound : bound - a[axis];
    const double db = keep_above ? b[axis] - bound : bound - b[axis];
    if (da >= 0.0) out[n++] = a;
    if ((da >= 0.0) != (db >= 0.0)) out[n++] = a + (da / (da - db)) * (b - a);
  }
  return n;
}

}  // namespace mpmvv
