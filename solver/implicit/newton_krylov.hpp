// F(u) = 0 by SUNDIALS KINSOL: inexact Newton with a line search, the Newton
// systems solved by GMRES (SPGMR) with Jacobian-vector products by difference
// quotients of F (matrix-free) and a right preconditioner the caller supplies
// (an assembled approximate tangent, factorized). Every SUNDIALS call is
// checked; the handles are owned here.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace mpmvv {

struct NewtonKrylovOptions {
  double tolerance = 1e-10;      // on max |F_i| / force_scale (KINSOL's scaled function norm)
  double force_scale = 1.0;      // the scale of F
  double step_scale = 1.0;       // the scale of u
  long max_iterations = 50;      // Newton iterations
  int krylov_dimension = 60;     // GMRES subspace (restarts beyond it)
};

struct NewtonKrylovResult {
  bool converged = false;
  std::string message;           // KINSOL's return flag when it did not
  long iterations = 0;           // Newton
  long linear_iterations = 0;    // GMRES
  long residual_evaluations = 0;
  long preconditioner_setups = 0;
  double residual_norm = 0.0;    // max |F_i| / force_scale at the end
};

struct NewtonKrylovProblem {
  // f = F(u); false when F cannot be evaluated there (KINSOL shortens the step).
  std::function<bool(const std::vector<double>& u, std::vector<double>& f)> residual;
  // Builds the preconditioner at u (called when KINSOL refreshes it).
  std::function<void(const std::vector<double>& u)> setup;
  // v <- M^-1 v.
  std::function<void(std::vector<double>& v)> solve;
};

// Solves from u (the initial guess) in place.
NewtonKrylovResult solve_newton_krylov(const NewtonKrylovProblem& problem, std::vector<double>& u,
                                       const NewtonKrylovOptions& options);

}  // namespace mpmvv
