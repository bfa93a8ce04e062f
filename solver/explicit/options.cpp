// What make_stepper refuses before it builds a stepper: options that do not
// go together, and particles or stages that miss what the options need.
#include "options.hpp"

#include "../explicit_stepper.hpp"

#include <cstdint>
#include <stdexcept>

#include <fmt/format.h>

#include "../shape/bspline.hpp"
#include "../shape/cpdi_exact.hpp"

namespace mpmvv {

void check_domain_outlines(const Particles& P, Method method) {
  if (P.domain_first.empty() && P.domain_vertex.empty()) return;
  if (method != Method::cpdi_exact)
    throw std::invalid_argument(fmt::format("particle outlines serve method cpdi-exact only, not {}", to_string(method)));
  if (P.domain_first.size() != P.size() + 1 || P.domain_first.front() != 0 ||
      P.domain_first.back() != P.domain_vertex.size())
    throw std::invalid_argument("particle outlines need one start per particle and an end");
  for (std::size_t p = 0; p < P.size(); ++p) {
    const std::uint32_t count = P.domain_first[p + 1] - P.domain_first[p];
    if (P.domain_first[p + 1] < P.domain_first[p] || (count != 0 && count < 3) ||
        count > std::uint32_t(CpdiExactShape::kMaxOutline))
      throw std::invalid_argument(fmt::format("particle {} has an outline of {} points; an outline has 3 to {}", p,
                                              int(P.domain_first[p + 1]) - int(P.domain_first[p]),
                                              CpdiExactShape::kMaxOutline));
  }
}

void check_explicit_options(const Model& model, const SolverOptions& options, const SceneStages& stages) {
  const std::size_t n = model.particles.size();
  if (!(stages.damping >= 0.0)) throw std::invalid_argument("damping must be zero or positive");
  if (!(options.split_domains_beyond >= 0.0))
    throw std::invalid_argument("split_domains_beyond must be zero (never) or a positive number of cells");
  const bool bspline = options.method == Method::bspline || options.method == Method::bspline_cubic;
  if (bspline && options.geometry != Geometry::plane_strain)
    throw std::invalid_argument(fmt::format("method {} is plane strain only: in r-z a particle near the axis would "
                                            "weigh nodes at r < 0", to_string(options.method)));
  if (options.split_domains_beyond > 0.0) {
    if (options.method != Method::cpdi && !(options.method == Method::cpdi_exact && options.cpdi_domain == CpdiDomain::corners))
      throw std::invalid_argument("split_domains_beyond is for method cpdi, or cpdi-exact with cpdi_domain = corners "
                                  "(a split halves a parallelogram or a quadrilateral, not an outline)");
    if (options.geometry != Geometry::plane_strain)
      throw std::invalid_argument("split_domains_beyond is plane strain only");
    if (stages.second_body > 0) throw std::invalid_argument("split_domains_beyond serves one body only");
  }
  // Below a right angle: the rectangle's orientation is the principal axes',
  // which a square domain does not have (round-off would pick them).
  if (!(options.min_domain_angle >= 0.0 && options.min_domain_angle < 90.0))
    throw std::invalid_argument("min_domain_angle is an angle in degrees from 0 (never) to below 90");
  if (options.min_domain_angle > 0.0) {
    if (options.method != Method::cpdi) throw std::invalid_argument("min_domain_angle is for method cpdi only");
    if (options.geometry != Geometry::plane_strain)
      throw std::invalid_argument("min_domain_angle is plane strain only (in r-z the domain's moments carry "
                                  "the weight r)");
    if (options.formulation == Formulation::total)
      throw std::invalid_argument("min_domain_angle serves the updated formulation: total Lagrangian domains "
                                  "never deform");
  }
  if (options.cpdi_domain == CpdiDomain::corners) {
    if (options.method != Method::cpdi && options.method != Method::cpdi_exact)
      throw std::invalid_argument("cpdi_domain = corners is for methods cpdi and cpdi-exact");
    if (options.geometry != Geometry::plane_strain)
      throw std::invalid_argument("cpdi_domain = corners is plane strain only");
    if (options.formulation == Formulation::total)
      throw std::invalid_argument("cpdi_domain = corners serves the updated formulation: total Lagrangian domains "
                                  "never deform");
    if (options.min_domain_angle > 0.0)
      throw std::invalid_argument("min_domain_angle turns parallelograms; corner domains (cpdi_domain = corners) "
                                  "keep the quadrilateral their corners make");
    if (stages.second_body > 0)
      throw std::invalid_argument("cpdi_domain = corners serves one body (each body's corners would read its own "
                                  "grid field)");
  }
  if (options.formulation == Formulation::total) {
    // What the reference grid cannot do yet, or does not need.
    if (options.split_domains_beyond > 0.0)
      throw std::invalid_argument("split_domains_beyond serves the updated formulation: total Lagrangian domains "
                                  "never deform");
    if (options.geometry != Geometry::plane_strain)
      throw std::invalid_argument("the total Lagrangian formulation is plane strain only");
    if (stages.contact || stages.second_body > 0)
      throw std::invalid_argument("the total Lagrangian formulation has no contact: its grid moves with one body");
    if (options.dilatation == Dilatation::cell_averaged)
      throw std::invalid_argument("the total Lagrangian formulation takes dilatation = particle or node-smoothed "
                                  "(cell-averaged bins particles by their current cell)");
  }
  if (!(options.bulk_viscosity_linear >= 0.0 && options.bulk_viscosity_quadratic >= 0.0))
    throw std::invalid_argument("the bulk viscosity coefficients must be zero (none) or positive");
  if (options.velocity_transfer == VelocityTransfer::apic) {
    // The affine field is x_g - x_p in the current configuration; the total
    // formulation weighs reference positions, and in r-z the weights are not
    // shown to reproduce linear fields.
    if (options.formulation == Formulation::total)
      throw std::invalid_argument("velocity_transfer = apic serves the updated formulation (the total formulation "
                                  "weighs the particles at their reference positions)");
    if (options.geometry != Geometry::plane_strain)
      throw std::invalid_argument("velocity_transfer = apic is plane strain only");
  }
  if (stages.contact && !stages.contact->displacement)
    throw std::invalid_argument("a contact master needs its displacement d(t)");
  if (stages.second_material) {
    if (stages.second_material_from == 0 || stages.second_material_from >= n)
      throw std::invalid_argument("each of the two materials must hold particles: 0 < second_material_from < n");
    if (options.split_domains_beyond > 0.0)
      throw std::invalid_argument("split_domains_beyond serves one material only (halves are appended at the end)");
  }
  if (stages.second_body > 0) {
    if (stages.second_body >= n) throw std::invalid_argument("the second body holds no particle");
    if (options.scheme != Scheme::usl) throw std::invalid_argument("two bodies in contact step with usl only");
    if (stages.contact) throw std::invalid_argument("two bodies in contact cannot also touch a rigid master");
    if (!stages.rest_points.empty())
      throw std::invalid_argument("rest points serve one body (each body's grid field would need its own)");
  }
  if (stages.traction) {
    // The sides are placed by x_p + F_p (A - X_p) and shared by the grid's
    // bilinear basis or CPDI's corners (traction.hpp).
    if (options.geometry != Geometry::plane_strain)
      throw std::invalid_argument("boundary tractions are plane strain only (r-z would weigh each side by its radius)");
    if (bspline)
      throw std::invalid_argument(fmt::format("boundary tractions are shared by the grid's bilinear basis, which method {} "
                                              "does not interpolate with", to_string(options.method)));
    if (options.cpdi_domain == CpdiDomain::corners)
      throw std::invalid_argument("boundary tractions place a domain's side by F_p, and corner domains move their "
                                  "corners apart from it: use cpdi_domain = \"convected\"");
    if (stages.second_body > 0) throw std::invalid_argument("boundary tractions serve one body");
    for (const BoundaryEdge& e : stages.traction->edges())
      if (e.particle >= n)
        throw std::invalid_argument(fmt::format("a boundary traction names particle {}, beyond the {} seeded", e.particle, n));
  }
  for (const NodeConstraint& c : stages.constraints) {
    if (c.axis != 0 && c.axis != 1) throw std::invalid_argument("a node constraint's axis is 0 (x) or 1 (y)");
    if (!c.displacement) throw std::invalid_argument("a node constraint needs its displacement u(t)");
    for (std::size_t node : c.nodes)
      if (node >= model.grid.node_count())
        throw std::invalid_argument(fmt::format("a node constraint names node {}, beyond the grid's {} nodes", node,
                                                model.grid.node_count()));
  }
  if (n == 0) throw std::invalid_argument("the scene seeded no particles");
  if (options.method != Method::linear && !bspline && model.particles.half_size.size() != n)
    throw std::invalid_argument(fmt::format("method {} needs a particle domain (half_size) for every particle",
                                            to_string(options.method)));
  check_domain_outlines(model.particles, options.method);
  if (options.cpdi_domain == CpdiDomain::corners && !model.particles.domain_first.empty())
    throw std::invalid_argument("corner domains replace particle outlines: seed them without outlines (the corners "
                                "start from each particle's parallelogram)");
  if (bspline) {
    auto check = [&](const auto shape) {
      for (std::size_t p = 0; p < n; ++p)
        if (!shape.clear_of_walls(p))
          throw std::invalid_argument(fmt::format(
              "method {}: the particle at ({:.6g}, {:.6g}) lies within {:g} cells (h = {:.6g}) of a wall, where its "
              "support would reach the mirrored ghost nodes (shape/bspline.hpp); keep the body that far from the "
              "walls, or take another method",
              to_string(options.method), model.particles.position[p].x(), model.particles.position[p].y(),
              shape.wall_clearance, model.grid.h));
    };
    if (options.method == Method::bspline)
      check(BsplineShape::bind(model.grid, model.particles));
    else
      check(CubicBsplineShape::bind(model.grid, model.particles));
  }
  if (options.geometry == Geometry::axisymmetric) {
    if (model.particles.hoop_stretch.size() != n || model.particles.hoop_stress.size() != n)
      throw std::invalid_argument("an axisymmetric run needs the hoop stretch and hoop stress of every particle");
    for (std::size_t p = 0; p < n; ++p)
      if (!(model.particles.position[p].x() > 0.0))
        throw std::invalid_argument(fmt::format("an axisymmetric run needs every particle off the axis (r > 0); "
                                                "particle {} is at r = {}", p, model.particles.position[p].x()));
    if (model.grid.wall_lower().x() != 0.0)
      throw std::invalid_argument("an axisymmetric grid has its left wall on the axis r = 0");
  }
}

}  // namespace mpmvv
