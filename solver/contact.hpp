// Frictionless contact of the scene's body with a rigid body of exact shape
// moved by a prescribed translation: the master of specified-velocity contact
// (002_c3305cb8b1bc1490.txt section 1.7.4, eq. 1.110), whose velocity the
// grid nodes in contact take along the master's normal, while their tangential
// velocity is left free. Contact is decided from the exact geometry, not from
// shared grid mass (which would see contact a cell early): a node is in
// contact when the domain of a particle it carries would cross the master's
// surface during the step, and its normal velocity is then limited to closing
// exactly the remaining gap (eq. 1.112's "approaching" condition with the
// gap as the measure). The grid force this takes is the contact force.
#pragma once

#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include "grid.hpp"
#include "parallel.hpp"
#include "particles.hpp"
#include "shape/stencil.hpp"

namespace mpmvv {

struct RigidBody {
  enum class Kind { disk, half_plane };
  Kind kind = Kind::disk;
  Vec2 point = Vec2::Zero();   // disk: the centre; half-plane: a point of its surface (at t = 0)
  double radius = 0.0;         // disk
  Vec2 outward = Vec2(0, 1);   // half-plane: unit normal pointing out of the rigid body
  std::function<Vec2(double)> displacement;  // of the body, d(0) = 0 [m]

  // Signed distance of x from the surface at time t: negative inside the body.
  double distance(const Vec2& x, double t) const {
    const Vec2 p = point + displacement(t);
    return kind == Kind::disk ? (x - p).norm() - radius : (x - p).dot(outward);
  }
  // The outward unit normal of the surface nearest x.
  Vec2 normal(const Vec2& x, double t) const {
    if (kind == Kind::half_plane) return outward;
    const Vec2 r = x - (point + displacement(t));
    const double n = r.norm();
    return n > 0.0 ? Vec2(r / n) : Vec2(0.0, 1.0);
  }
};

// The contact force on the scene's body at each grid node of the last step
// (zero where there was none) [N per unit depth], and its sum.
struct ContactForces {
  std::vector<Vec2> node_force;
  Vec2 total = Vec2::Zero();
};

// Work arrays of the contact stage, allocated once per run.
struct ContactScratch {
  std::vector<double> particle_gap;  // signed distance of each particle's domain from the master
  std::vector<double> node_gap;      // the smallest over the particles a node carries; +inf elsewhere
};

// The gap of every node that can touch the master: a node carrying a
// particle whose domain lies within `reach` of the master gets the smallest
// signed distance of such a domain from the master's surface (a domain's
// nearest point is a corner: a parallelogram's extreme along a direction is a
// corner). All the nodes such a particle touches take part, not only those
// on the body's boundary: measured on the Hertz scene (a / h = 4 and 8),
// leaving the inner ones free made the contact 1.3-1.9 % too wide and the
// peak 2-3 % too low, against 0.9 % and 0.07 % with them.
template <class Shape>
void node_contact_gaps(const RigidBody& master, const Shape& shape, const Particles& P, const GridGeometry& grid,
                       double t, double reach, ContactScratch& scratch) {
  const std::size_t n = P.size();
  scratch.particle_gap.resize(n);
  scratch.node_gap.assign(grid.node_count(), std::numeric_limits<double>::infinity());
#pragma omp parallel for schedule(static)
  for (std::size_t p = 0; p < n; ++p) {
    const Mat2 s = shape.domain(p);
    double gap = std::numeric_limits<double>::infinity();
    for (const double a : {-1.0, 1.0})
      for (const double b : {-1.0, 1.0})
        gap = std::min(gap, master.distance(P.position[p] + a * s.col(0) + b * s.col(1), t));
    scratch.particle_gap[p] = gap;
  }
  Stencil<Shape::stencil_size> st;
  for (std::size_t p = 0; p < n; ++p) {
    if (scratch.particle_gap[p] > reach) continue;
    shape.evaluate(p, st);
    for (int k = 0; k < st.count; ++k)
      if (st.weight[k] > 0.0)
        scratch.node_gap[std::size_t(st.node[k])] = std::min(scratch.node_gap[std::size_t(st.node[k])], scratch.particle_gap[p]);
  }
}

// After the grid update (velocities at the end of the kick): limits the normal
// velocity of the nodes in contact, v_g.n >= V.n - gap_g / dt, with V the
// master's velocity over the step and n its outward normal at the node, and
// books the force m_g dv / kick.
template <class Shape>
void apply_rigid_contact(const RigidBody& master, const Shape& shape, const Particles& P, const GridGeometry& grid,
                         GridFields& g, double t, double dt, double kick, ContactScratch& scratch,
                         ContactForces& out) {
  const std::size_t nodes = g.mass.size();
  out.node_force.assign(nodes, Vec2::Zero());
  out.total.setZero();
  const Vec2 V = (master.displacement(t + dt) - master.displacement(t)) / dt;
  // A particle farther than this cannot reach the master in one step (a step
  // moves less than a cell).
  node_contact_gaps(master, shape, P, grid, t, 2.0 * grid.h + V.norm() * dt, scratch);
  for (std::size_t i = 0; i < nodes; ++i) {
    if (!(g.mass[i] > 0.0) || !std::isfinite(scratch.node_gap[i])) continue;
    const int ix = int(i % std::size_t(grid.nodes_x())), iy = int(i / std::size_t(grid.nodes_x()));
    const Vec2 normal = master.normal(grid.node_position(ix, iy), t);
    const double closing = (g.velocity[i] - V).dot(normal);  // negative: approaching
    const double limit = -scratch.node_gap[i] / dt;
    if (closing >= limit) continue;
    const Vec2 dv = (limit - closing) * normal;
    g.velocity[i] += dv;
    g.acceleration[i] += dv / kick;
    out.node_force[i] = g.mass[i] * dv / kick;
    out.total += out.node_force[i];
  }
}

// ---------------------------------------------------------------- two bodies

// What a second deformable body adds to a step (multi-velocity MPM): particles
// [first, n) are that body, with their own grid velocity field, and each
// body's normal at the nodes comes from its mass gradient. first = 0: one body.
struct SecondBody {
  std::size_t first = 0;
  GridFields fields;                           // the second body's grid field
  std::vector<Vec2> gradient_a, gradient_b;    // both bodies' mass gradients, eq. 1.107
  std::vector<std::vector<Vec2>> buffers;      // mass_gradient_to_grid's per-thread sums

  SecondBody(std::size_t first_particle, std::size_t nodes, int threads) : first(first_particle) {
    if (first == 0) return;
    fields.resize(nodes);
    gradient_a.assign(nodes, Vec2::Zero());
    gradient_b.assign(nodes, Vec2::Zero());
    buffers.resize(std::size_t(threads));
  }
};

// The normal of a body at the nodes, eq. 1.107: n_g = sum_p m_p G_gp, with
// G_gp the gradient of node g's function at the particles: beside the body it
// points out of it (the node's function grows away from the particles). One
// scatter buffer per thread, summed in thread order.
template <class Shape>
void mass_gradient_to_grid(const Shape& shape, const Particles& P, std::size_t first, std::size_t last,
                           std::vector<std::vector<Vec2>>& buffers, std::vector<Vec2>& gradient) {
  const std::size_t nodes = gradient.size();
  const int threads = int(buffers.size());
#pragma omp parallel num_threads(threads)
  {
    std::vector<Vec2>& own = buffers[std::size_t(thread_id())];
    own.assign(nodes, Vec2::Zero());
    Stencil<Shape::stencil_size> s;
#pragma omp for schedule(static)
    for (std::size_t p = first; p < last; ++p) {
      shape.evaluate(p, s);
      for (int k = 0; k < s.count; ++k) own[std::size_t(s.node[k])] += P.mass[p] * s.gradient[k];
    }
#pragma omp for schedule(static)
    for (std::size_t i = 0; i < nodes; ++i) {
      Vec2 sum = Vec2::Zero();
      for (int t = 0; t < threads; ++t) sum += buffers[std::size_t(t)][i];
      gradient[i] = sum;
    }
  }
}

// Frictionless contact of two deformable bodies through their own grid
// velocity fields (multi-velocity MPM, 002_c3305cb8b1bc1490.txt section 1.7):
// at a node both bodies reach, with the centre-of-mass velocity
// v_cm = (m_a v_a + m_b v_b) / (m_a + m_b) (eq. 1.105) and the contact normal
// n, the unit of n_a - n_b (outward from body a, averaged over both bodies'
// normals, eqs. 1.107 and 1.117), the bodies approach when (v_a - v_cm).n > 0 (eq. 1.112);
// then each loses its normal velocity relative to v_cm (eqs. 1.113-1.114 with
// no friction), which conserves momentum node by node, and the tangential
// velocities are left as they are. Contact is decided from the grid: the
// bodies touch when both reach a node, which is up to a cell early. The force
// on body a is m_a dv_a / kick (body b takes its opposite).
inline void apply_body_contact(GridFields& a, GridFields& b, const std::vector<Vec2>& gradient_a,
                               const std::vector<Vec2>& gradient_b, double kick, ContactForces& out) {
  const std::size_t nodes = a.mass.size();
  out.node_force.assign(nodes, Vec2::Zero());
  out.total.setZero();
  for (std::size_t i = 0; i < nodes; ++i) {
    if (!(a.mass[i] > 0.0 && b.mass[i] > 0.0)) continue;
    const Vec2 d = gradient_a[i] - gradient_b[i];
    const double length = d.norm();
    if (!(length > 0.0)) continue;
    const Vec2 n = d / length;
    const Vec2 v_cm = (a.mass[i] * a.velocity[i] + b.mass[i] * b.velocity[i]) / (a.mass[i] + b.mass[i]);
    const double approach = (a.velocity[i] - v_cm).dot(n);
    if (!(approach > 0.0)) continue;
    const Vec2 dv_a = -approach * n;
    const Vec2 dv_b = -(b.velocity[i] - v_cm).dot(n) * n;
    a.velocity[i] += dv_a;
    a.acceleration[i] += dv_a / kick;
    b.velocity[i] += dv_b;
    b.acceleration[i] += dv_b / kick;
    out.node_force[i] = a.mass[i] * dv_a / kick;
    out.total += out.node_force[i];
  }
}

}  // namespace mpmvv
