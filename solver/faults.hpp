// Deliberate faults: mistakes a developer could make in the explicit step,
// injected on purpose to show that a verification gate catches each of them
// (tools/app/fault.hpp reads them from MPMVV_FAULT; tests/fault_catalogue.cpp
// shows which check catches which). A real run has none: the stepper tests
// the fault once per stage, never per particle, and the passes below run only
// under their fault.
#pragma once

#include <algorithm>
#include <cstring>
#include <vector>

#include "particles.hpp"
#include "tensor.hpp"

namespace mpmvv {

enum class SolverFault {
  none,
  // Shape functions and their gradients (shape/cpdi.hpp):
  cpdi_weight,    // the corner shares of S_gp are (1/4)(1 + 0.1 xi_c), not 1/4 (eq. 1.95)
  cpdi_gradient,  // the corner gradients carry (1/4) 1.04 xi_c, not xi_c / 4 (eq. 1.100)
  cpdi_shear_sign,  // the cross terms of s^-T lose their minus: [[s11, s10], [s01, s00]] / det s (eq. 1.100)
  linear_gradient,  // linear MPM's hat gradients scaled by 1.04 (eq. 1.89)
  gimp_gradient,    // uGIMP's 1D weight derivatives scaled by 1.04 (eq. 1.92)
  // The deformation gradient and volume updates (stages.hpp: grid_to_particles):
  deformation_transpose,  // F_p <- (I + dt L_p^T) F_p, the velocity gradient transposed (eq. 1.74)
  frozen_volume,          // V_p stays V_p0: the volume update (eq. 1.75) left out
  // The internal force (eq. 1.70):
  lagged_stress,  // the force of step n from the stress of the update before (sigma_{n-1})
  // The r-z hoop term of the internal force:
  no_hoop_stress,  // sigma_theta <S_g / r> left out: the hoop stress is zero
  // The body force's point and time:
  force_at_current_position,  // b(x_p, t), the manufactured force read at the current point, not at X_p
  lagged_force_time,          // b(X_p, t_{n-1}), read at the time of the step before
  // The time step:
  frozen_time_step,  // the CFL signal speed of the first step kept for the whole run
  // Mass lumping:
  consistent_mass,  // node mass sum_p m_p S_gp^2, the consistent matrix's diagonal, not its row sum (eq. 1.69)
  // The particle velocity update:
  pic_velocity,  // v_p <- sum_g S_gp v_g^L, the grid's velocity, not v_p + dt sum_g S_gp a_g (eq. 1.76)
  // The material:
  kirchhoff_stress,  // J sigma, the Kirchhoff stress, where the Cauchy stress belongs
  wrong_shear_modulus,   // the stress update weighs mu 1.05 (every shear modulus of the material), not mu
  non_objective_stress,  // sigma(sym F), the stress of F's symmetric part: F's rotation read as stretch
  // The walls (stages.hpp: apply_walls):
  swapped_walls,  // a wall holds the tangential component at zero and lets the normal one free
  mirrored_wall,  // a wall node's normal velocity and acceleration reflected (-v_n), not set to zero
  // The velocity transfer (stages.hpp: velocities_from_grid):
  apic_transpose,  // APIC's affine matrix C_p stored transposed (C_p^T for sum_g v_g G_gp^T, eq. 1.76)
  // The boundary tractions (traction.hpp):
  traction_factor,  // the boundary traction's force scaled by 1.05 (the side's length counted 5% long)
};

inline constexpr SolverFault kSolverFaults[] = {
    SolverFault::cpdi_weight,       SolverFault::cpdi_gradient,     SolverFault::deformation_transpose,
    SolverFault::frozen_volume,     SolverFault::lagged_stress,     SolverFault::no_hoop_stress,
    SolverFault::force_at_current_position, SolverFault::lagged_force_time, SolverFault::frozen_time_step,
    SolverFault::consistent_mass,   SolverFault::pic_velocity,      SolverFault::kirchhoff_stress,
    SolverFault::swapped_walls,     SolverFault::cpdi_shear_sign,   SolverFault::linear_gradient,
    SolverFault::gimp_gradient,     SolverFault::wrong_shear_modulus, SolverFault::non_objective_stress,
    SolverFault::mirrored_wall,     SolverFault::apic_transpose,    SolverFault::traction_factor};

inline const char* to_string(SolverFault f) {
  switch (f) {
    case SolverFault::none: return "";
    case SolverFault::cpdi_weight: return "cpdi-weight";
    case SolverFault::cpdi_gradient: return "cpdi-gradient";
    case SolverFault::deformation_transpose: return "deformation-transpose";
    case SolverFault::frozen_volume: return "frozen-volume";
    case SolverFault::lagged_stress: return "lagged-stress";
    case SolverFault::no_hoop_stress: return "no-hoop-stress";
    case SolverFault::force_at_current_position: return "force-at-current-position";
    case SolverFault::lagged_force_time: return "lagged-force-time";
    case SolverFault::frozen_time_step: return "frozen-time-step";
    case SolverFault::consistent_mass: return "consistent-mass";
    case SolverFault::pic_velocity: return "pic-velocity";
    case SolverFault::kirchhoff_stress: return "kirchhoff-stress";
    case SolverFault::swapped_walls: return "swapped-walls";
    case SolverFault::cpdi_shear_sign: return "cpdi-shear-sign";
    case SolverFault::linear_gradient: return "linear-gradient";
    case SolverFault::gimp_gradient: return "gimp-gradient";
    case SolverFault::wrong_shear_modulus: return "wrong-shear-modulus";
    case SolverFault::non_objective_stress: return "non-objective-stress";
    case SolverFault::mirrored_wall: return "mirrored-wall";
    case SolverFault::apic_transpose: return "apic-transpose";
    case SolverFault::traction_factor: return "traction-factor";
  }
  return "?";
}

// The fault of that name, or none for a name that is not one.
inline SolverFault solver_fault_named(const char* name) {
  for (SolverFault f : kSolverFaults)
    if (std::strcmp(name, to_string(f)) == 0) return f;
  return SolverFault::none;
}

// cpdi-gradient's factor on the corner gradients and cpdi-weight's skew of the
// corner shares.
inline constexpr double kFaultyCpdiGradientScale = 1.04;
inline constexpr double kFaultyCpdiWeightSkew = 0.1;
// linear-gradient's and gimp-gradient's factor on the shape gradients (as
// cpdi-gradient's), wrong-shear-modulus's on mu and traction-factor's on the
// boundary traction's force.
inline constexpr double kFaultyGridGradientScale = 1.04;
inline constexpr double kFaultyShearModulusScale = 1.05;
inline constexpr double kFaultyTractionScale = 1.05;

// wrong-shear-modulus: the material with every shear modulus scaled (mu; a
// Mooney-Rivlin solid's c1 and c2, whose sum is mu / 2); the bulk terms kept.
template <class Material>
Material with_faulty_shear_modulus(Material m) {
  if constexpr (requires { m.mu; }) m.mu *= kFaultyShearModulusScale;
  if constexpr (requires { m.c1; m.c2; }) {
    m.c1 *= kFaultyShearModulusScale;
    m.c2 *= kFaultyShearModulusScale;
  }
  return m;
}

// non-objective-stress, before a stress update: F_p <- (F_p + F_p^T) / 2 for
// every particle, the true F_p kept in `held` (and put back after). A rigid
// rotation by theta then reads as the stretch cos theta.
inline void symmetric_deformation(Particles& P, std::vector<Mat2>& held) {
  held = P.deformation_gradient;
  for (Mat2& F : P.deformation_gradient) F = Mat2(0.5 * (F + F.transpose()));
}

// apic-transpose, after a velocity update: C_p <- C_p^T.
inline void transpose_affine_velocities(Particles& P) {
  for (Mat2& C : P.affine_velocity) C.transposeInPlace();
}

// deformation-transpose, after an update F_new = (I + dt L) F_old: the
// increment I + dt L = F_new F_old^-1 is applied transposed instead.
inline void transpose_deformation_increments(Particles& P, const std::vector<Mat2>& before) {
  const std::size_t n = std::min(before.size(), P.size());
  for (std::size_t p = 0; p < n; ++p) {
    const Mat2& F = before[p];
    Mat2 inverse;
    inverse << F(1, 1), -F(0, 1), -F(1, 0), F(0, 0);
    const Mat2 increment = P.deformation_gradient[p] * inverse / determinant(F);
    P.deformation_gradient[p] = increment.transpose() * before[p];
  }
}

// kirchhoff-stress, after a stress update: sigma_p <- J_p sigma_p (and the hoop stress).
inline void stress_times_dilatation(Particles& P) {
  for (std::size_t p = 0; p < P.size(); ++p) {
    const double J = P.volume[p] / P.reference_volume[p];
    P.stress[p] *= J;
    if (!P.hoop_stress.empty()) P.hoop_stress[p] *= J;
  }
}

}  // namespace mpmvv
