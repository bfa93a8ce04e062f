// The total Lagrangian formulation (formulation = "total"): the grid is the
// body's reference configuration, each particle is weighed at its reference
// position X_p for the whole run, and the grid's velocity is the velocity of
// the material at the grid's reference points. With G0_gp the reference
// gradient of a method's basis at X_p, the step's stages keep their form with
//   G_gp = F_p^-T G0_gp,
// because then (002_c3305cb8b1bc1490.txt eqs. 1.70, 1.73-1.74)
//   V_p sigma_p G_gp = V_p0 J_p sigma_p F_p^-T G0_gp = V_p0 P_p G0_gp,
//     the internal force of the first Piola-Kirchhoff stress P over the
//     reference domain, and
//   (I + dt sum_g v_g (x) G_gp) F_p = F_p + dt sum_g v_g (x) G0_gp,
//     the reference gradient of the grid's velocity.
// F_p = I + sum_g u_g (x) G0_gp then follows the grid's displacement exactly,
// the internal force is the gradient of the stored energy sum V_p0 psi(F_p)
// with respect to the grid's displacement, and its linearization is
// symmetric: a stressed state has no modes that grow by themselves. Under
// the updated formulation the weights follow the particles through the
// fixed grid, and the linearization of a stressed state is not symmetric
// (tests/test_stable_step.cpp measures it).
//
// The particles never leave the reference grid, so no cell crossing happens;
// the formulation suits bodies whose material points keep their neighbours
// (no fracture, no mixing), such as every manufactured scene here. Plane
// strain. The reference basis is the bilinear hat at X_p (linear MPM; the
// particle a point, the basis the grid's own, as in the total Lagrangian MPM
// literature), or uGIMP, whose square reference domains tile the body, or
// CPDI over the same squares (corner interpolation of the grid
// basis, eq. 1.95 with F = I), or exact CPDI over each particle's exact
// reference outline (a cut piece of a curved body keeps its true shape), or
// the grid's quadratic B-splines at X_p (shape/bspline.hpp; a point, like the
// hat, with a C1 basis one order richer): the
// domains never deform, so CPDI's large-shear trouble (stretched domains,
// gradients beyond the grid basis) never arises, and the basis is fixed for
// the run.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "../particles.hpp"
#include "cpdi.hpp"
#include "cpdi_exact.hpp"
#include "gimp.hpp"
#include "linear.hpp"
#include "stencil.hpp"

namespace mpmvv {

template <class Reference>
struct TotalLagrangianShapeT {
  static_assert(Reference::geometry == Geometry::plane_strain, "the total Lagrangian formulation is plane strain");
  static constexpr int stencil_size = Reference::stencil_size;
  static constexpr const char* name = Reference::name;
  static constexpr Geometry geometry = Reference::geometry;
  static constexpr bool reads_deformation_gradient = true;
  static constexpr bool gradients_beyond_grid_basis = false;  // G0 is the reference basis's own
  static constexpr bool total_lagrangian = true;
  static constexpr bool has_domain = Reference::has_domain;
  using GridBasis = typename Reference::GridBasis;  // on the reference grid

  Reference reference;             // the method's basis at X_p
  const Mat2* deformation_gradient;

  // `deformation_gradient` may point to a copy of F taken at the start of a
  // step, so that every transfer of the step maps the gradients alike.
  static TotalLagrangianShapeT bind(const GridGeometry& grid, const Particles& particles,
                                    const Mat2* deformation_gradient = nullptr, double gradient_scale = 1.0) {
    Reference r = Reference::bind(grid, particles, nullptr, gradient_scale);
    r.position = particles.reference_position.data();
    // CPDI weighs the reference domain: F = I (shape/cpdi.hpp).
    if constexpr (Reference::reads_deformation_gradient) r.deformation_gradient = nullptr;
    return {r, deformation_gradient ? deformation_gradient : particles.deformation_gradient.data()};
  }

  void evaluate(std::size_t p, Stencil<stencil_size>& s) const {
    reference.evaluate(p, s);
    const Mat2& F = deformation_gradient[p];
    // F^-T = [[F11, -F10], [-F01, F00]] / det F.
    const double inv_det = 1.0 / determinant(F);
    for (int k = 0; k < s.count; ++k) {
      const Vec2 g = s.gradient[k];
      s.gradient[k] = inv_det * Vec2(F(1, 1) * g.x() - F(1, 0) * g.y(), F(0, 0) * g.y() - F(0, 1) * g.x());
    }
  }

  // The reference point lies where it always did; the run stops on the
  // state alone (J, NaN), which the health scan checks.
  bool inside(std::size_t p) const { return reference.inside(p); }
  bool clear_of_walls(std::size_t p) const
    requires requires(const Reference& r, std::size_t q) { r.clear_of_walls(q); }
  {
    return reference.clear_of_walls(p);
  }

  // The current image of the reference domain, F_p times its half-vectors.
  Mat2 domain(std::size_t p) const { return deformation_gradient[p] * reference.domain(p); }

  // How much the particle's reference cell has shrunk along its most
  // compressed direction: the smallest singular value of F_p. A wave crosses
  // the current image of a cell, and the step must shrink with it.
  double cell_stretch(std::size_t p) const {
    const Mat2& F = deformation_gradient[p];
    // Singular values of a 2 x 2 matrix: sqrt of the eigenvalues of F^T F.
    const double a = F.col(0).squaredNorm(), b = F.col(0).dot(F.col(1)), d = F.col(1).squaredNorm();
    const double mean = 0.5 * (a + d), spread = std::sqrt(0.25 * (a - d) * (a - d) + b * b);
    return std::sqrt(std::max(mean - spread, 0.0));
  }
};

using TotalLagrangianLinearShape = TotalLagrangianShapeT<LinearShapeT<Geometry::plane_strain>>;
using TotalLagrangianGimpShape = TotalLagrangianShapeT<GimpShapeT<Geometry::plane_strain>>;
using TotalLagrangianCpdiShape = TotalLagrangianShapeT<CpdiShapeT<Geometry::plane_strain>>;
using TotalLagrangianCpdiExactShape = TotalLagrangianShapeT<CpdiExactShapeT<Geometry::plane_strain>>;

}  // namespace mpmvv
