// The implicit quasi-static step (002_c3305cb8b1bc1490.txt section 1.8 with
// the inertia term dropped): each step finds the grid displacement u_g that
// puts the particles in equilibrium under the loads at the step's end,
//   R(u) = f_int(u) - f_ext = 0,   f_int,g = sum_p V_p^n P~_p G_gp^n,
// in the configuration of the step's start (updated Lagrangian: the weights,
// gradients and CPDI domains stay those of x^n), with
//   dF_p = I + sum_g u_g (x) G_gp^n,  F_p = dF_p F_p^n,
//   P~_p = det(dF_p) sigma(F_p) dF_p^-T   (the first Piola stress on config n).
// The unknowns are the free components of the nodes the particles reach:
// walls fix the normal component and mirror the ghost nodes, node constraints
// prescribe theirs, and a rigid master in contact prescribes the normal
// component of the nodes in contact (the same gap rule as the explicit step,
// solver/contact.hpp), found by an active-set loop. R(u) = 0 is solved by
// KINSOL's Newton-Krylov method (newton_krylov.hpp) with matrix-free Jacobian
// products, right-preconditioned by the assembled small-strain tangent
// (sum_p V_p B^T C B, eq. 1.160 linearized) factorized by Eigen's sparse LDL^T.
#pragma once

#include <memory>

#include "solver/stepper.hpp"

namespace mpmvv {

struct StaticOptions {
  // max |R| over 2 mu h, the nodal force of a unit shear strain: the softest
  // mode's stiffness, so 1e-8 is a displacement error of about 1e-8 h
  // whatever lambda / mu (over (lambda + 2 mu) h the same bound let the
  // uniaxial bar at nu = 0.4999 stop 2500 times less equilibrated: error
  // 2.1e-4 against 2.9e-5 now). Where difference-quotient Jacobian products
  // (good to about sqrt(eps) of the lambda-sized forces) cannot go lower,
  // KINSOL stops on its step tolerance. The scene key newton_tolerance sets
  // it; Stepper::distance_to_equilibrium says how far from equilibrium it
  // leaves the last step.
  double tolerance = 1e-8;
  long max_iterations = 50;  // Newton iterations per solve
  int max_contact_passes = 30;
  // A load step whose solve fails (KINSOL cannot evaluate the residual at
  // the start, a line search that keeps meeting non-finite residuals, no
  // convergence) is taken again as two halves, each halved again the same
  // way, at most this many times: the start of a shorter step is nearer to
  // its equilibrium. 0: a failed step stops the run.
  int max_halvings = 6;
};

// Plane strain; every shape-function family; every material.
std::unique_ptr<Stepper> make_static_stepper(Model model, const SolverOptions& options, const MaterialModel& material,
                                             SceneStages stages, const StaticOptions& static_options);

}  // namespace mpmvv
