#include "seeding.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include "solver/parallel.hpp"

namespace mpmvv::app {

namespace {

struct Piece {
  Vec2 centroid;
  double area;      // int dA
  double moment_r;  // int x dA (r in r-z)
  std::vector<Vec2> outline;  // exact CPDI only: the clipped piece's outline (empty: the whole sub-cell)
};

// The outline of a piece and a sliver joined to it: a whole sub-cell's
// square where either has none, then the sliver's ring on a bridge
// (append_ring).
std::vector<Vec2> joined_outline(const Piece& piece, const Piece& sliver, double spacing) {
  auto ring = [&](const Piece& q) {
    if (!q.outline.empty()) return q.outline;
    const Vec2 l = 0.5 * spacing * Vec2(1.0, 1.0), lo = q.centroid - l, hi = q.centroid + l;
    return std::vector<Vec2>{lo, Vec2(hi.x(), lo.y()), hi, Vec2(lo.x(), hi.y())};
  };
  std::vector<Vec2> out = ring(piece);
  append_ring(out, ring(sliver));
  return out;
}

std::vector<Piece> pieces_of_cell(const SceneSetup& setup, const SeedingPlan& plan, int i, int j) {
  const GridGeometry& grid = setup.grid;
  const int ppd = plan.particles_per_direction;
  const double spacing = grid.h / ppd;
  std::vector<Piece> pieces;
  for (int b = 0; b < ppd; ++b)
    for (int a = 0; a < ppd; ++a) {
      const Vec2 lower = grid.node_position(i, j) + spacing * Vec2(a, b);
      const Vec2 centre = lower + 0.5 * spacing * Vec2(1.0, 1.0);
      const Piece whole{centre, spacing * spacing, spacing * spacing * centre.x(), {}};
#ifdef MPMVV_HAVE_CGAL
      if (plan.exact) {
        const Body& body = *setup.body;
        if (body.boundary_may_meet(lower, lower + spacing * Vec2(1.0, 1.0))) {
          const AreaMoments m = body.clip(lower, lower + spacing * Vec2(1.0, 1.0));
          if (m.area > 1e-14 * spacing * spacing) {
            if (plan.whole_cut_volume)
              pieces.push_back({m.centroid(), whole.area, whole.area * m.centroid().x(), {}});
            else
              pieces.push_back({m.centroid(), m.area, m.moment_x, {}});
            if (plan.outlines) pieces.back().outline = body.clip_outline(lower, lower + spacing * Vec2(1.0, 1.0),
                                                                       0.25 * spacing);
          }
        } else if (body.contains(centre)) {
          pieces.push_back(whole);
        }
        continue;
      }
#endif
      if (setup.contains(centre)) pieces.push_back(whole);
    }
  // Slivers join the largest piece of the cell.
  const double sliver = 0.1 * spacing * spacing;
  auto largest = std::max_element(pieces.begin(), pieces.end(),
                                  [](const Piece& x, const Piece& y) { return x.area < y.area; });
  if (largest != pieces.end()) {
    Piece merged = *largest;
    std::vector<Piece> kept;
    for (auto it = pieces.begin(); it != pieces.end(); ++it) {
      if (it == largest) continue;
      if (it->area < sliver) {
        merged.centroid = (merged.centroid * merged.area + it->centroid * it->area) / (merged.area + it->area);
        merged.area += it->area;
        merged.moment_r += it->moment_r;
        if (plan.outlines) merged.outline = joined_outline(merged, *it, spacing);
      } else {
        kept.push_back(*it);
      }
    }
    kept.push_back(merged);
    pieces = std::move(kept);
  }
  return pieces;
}

}  // namespace

Seeded seed_particles(const SceneSetup& setup, const SeedingPlan& plan, Particles& P) {
  const GridGeometry& grid = setup.grid;
  Seeded seeded;
  std::vector<Piece> pieces;
  for (int j = 0; j < grid.cells_y; ++j)
    for (int i = 0; i < grid.cells_x; ++i)
      for (const Piece& piece : pieces_of_cell(setup, plan, i, j)) pieces.push_back(piece);
  // A second material's particles after the first's, each in seeding order.
  if (setup.second_material) {
    const auto second = std::stable_partition(pieces.begin(), pieces.end(), [&setup](const Piece& piece) {
      return !setup.in_second_material(piece.centroid);
    });
    seeded.first_material_count = std::size_t(second - pieces.begin());
  }
  P.resize(pieces.size());
  const bool axisymmetric = setup.geometry == Geometry::axisymmetric;
  if (axisymmetric) {
    P.hoop_stretch.resize(pieces.size());
    P.hoop_stress.resize(pieces.size());
  }
  const double density = setup.solution->density();
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    const Vec2 X = pieces[p].centroid;
    const mms::ExactFields f = setup.solution->state(X, 0.0);
    const double reference_volume = axisymmetric ? pieces[p].moment_r : pieces[p].area;
    P.reference_position[p] = X;
    P.position[p] = f.position;
    P.velocity[p] = f.velocity;
    P.deformation_gradient[p] = f.deformation_gradient;
    P.stress[p] = f.cauchy_stress;
    P.reference_volume[p] = reference_volume;
    P.volume[p] = f.J * reference_volume;
    P.mass[p] = density * reference_volume;
    seeded.particle_volume += reference_volume;
    if (axisymmetric) {
      P.hoop_stretch[p] = f.hoop_stretch;
      P.hoop_stress[p] = f.cauchy_stress_33;
    }
  }
  if (plan.half_sizes) {
    P.half_size.resize(pieces.size());
    for (std::size_t p = 0; p < pieces.size(); ++p)
      P.half_size[p] = 0.5 * std::sqrt(pieces[p].area) * Vec2(1.0, 1.0);
  }
  if (plan.outlines) {
    P.domain_first.assign(pieces.size() + 1, 0);
    P.domain_vertex.clear();
    for (std::size_t p = 0; p < pieces.size(); ++p) {
      for (const Vec2& v : pieces[p].outline) P.domain_vertex.push_back(v - pieces[p].centroid);
      P.domain_first[p + 1] = std::uint32_t(P.domain_vertex.size());
    }
  }
  return seeded;
}

double exact_body_volume(const SceneSetup& setup) {
#ifdef MPMVV_HAVE_CGAL
  if (setup.body) {
    const AreaMoments m = setup.body->whole();
    return setup.geometry == Geometry::axisymmetric ? m.moment_x : m.area;
  }
#endif
  return std::numeric_limits<double>::quiet_NaN();
}

void refuse_what_cannot_fit(const SceneSetup& setup, const Config& config) {
  const GridGeometry& g = setup.grid;
  double area = (g.upper() - g.origin).prod();
#ifdef MPMVV_HAVE_CGAL
  if (setup.body) area = setup.body->whole().area;
#endif
  const double spacing = g.h / double(config.integer("particles_per_direction"));
  const double particles = area / (spacing * spacing);
  const double nodes = double(g.node_count());
  const int threads = max_threads();
  const double needed = 400.0 * particles + 8.0 * nodes * (11.0 + 5.0 * threads);
  const double machine = double(::sysconf(_SC_PHYS_PAGES)) * double(::sysconf(_SC_PAGESIZE));
  if (machine > 0.0 && needed > machine)
    throw ConfigError(fmt::format(
        "cells = {}, particles_per_direction = {} and threads = {} need about {:.3g} GiB ({:.3g} particles, {:.3g} "
        "grid nodes), more than this machine's {:.3g} GiB: use fewer cells, particles per direction or threads",
        config.integer("cells"), config.integer("particles_per_direction"), threads, needed / 1073741824.0,
        particles, nodes, machine / 1073741824.0));
}

}  // namespace mpmvv::app
