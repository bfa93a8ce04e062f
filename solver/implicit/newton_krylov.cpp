#include "newton_krylov.hpp"

#include <kinsol/kinsol.h>
#include <sunlinsol/sunlinsol_spgmr.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "sundials.hpp"

namespace mpmvv {

namespace {

struct Callbacks {
  const NewtonKrylovProblem* problem;
  std::vector<double> u, f, v;
  long evaluations = 0;
};

void copy_in(N_Vector x, std::vector<double>& to) {
  const sunindextype n = NV_LENGTH_S(x);
  std::copy(NV_DATA_S(x), NV_DATA_S(x) + n, to.begin());
}

int residual(N_Vector u, N_Vector f, void* data) {
  auto* c = static_cast<Callbacks*>(data);
  copy_in(u, c->u);
  ++c->evaluations;
  if (!c->problem->residual(c->u, c->f)) return 1;  // recoverable: KINSOL backs off
  for (double x : c->f)
    if (!std::isfinite(x)) return 1;
  std::copy(c->f.begin(), c->f.end(), NV_DATA_S(f));
  return 0;
}

int preconditioner_setup(N_Vector u, N_Vector, N_Vector, N_Vector, void* data) {
  auto* c = static_cast<Callbacks*>(data);
  copy_in(u, c->u);
  c->problem->setup(c->u);
  return 0;
}

int preconditioner_solve(N_Vector, N_Vector, N_Vector, N_Vector, N_Vector v, void* data) {
  auto* c = static_cast<Callbacks*>(data);
  copy_in(v, c->v);
  c->problem->solve(c->v);
  std::copy(c->v.begin(), c->v.end(), NV_DATA_S(v));
  return 0;
}

}  // namespace

NewtonKrylovResult solve_newton_krylov(const NewtonKrylovProblem& problem, std::vector<double>& u,
                                       const NewtonKrylovOptions& o) {
  using namespace sundials;
  NewtonKrylovResult r;
  const sunindextype n = sunindextype(u.size());
  if (n == 0) {
    r.converged = true;
    return r;
  }
  Context context;
  Vector x = serial_vector(n, context.context);
  Vector u_scale = serial_vector(n, context.context);
  Vector f_scale = serial_vector(n, context.context);
  std::copy(u.begin(), u.end(), NV_DATA_S(x.get()));
  N_VConst(1.0 / o.step_scale, u_scale.get());
  N_VConst(1.0 / o.force_scale, f_scale.get());
  LinearSolver gmres(
      check_pointer(SUNLinSol_SPGMR(x.get(), SUN_PREC_RIGHT, o.krylov_dimension, context.context), "SUNLinSol_SPGMR"));
  check(SUNLinSol_SPGMRSetMaxRestarts(gmres.get(), 20), "SUNLinSol_SPGMRSetMaxRestarts");
  Kinsol kinsol(check_pointer(KINCreate(context.context), "KINCreate"));
  Callbacks callbacks{&problem, std::vector<double>(u.size()), std::vector<double>(u.size()),
                      std::vector<double>(u.size())};
  check(KINInit(kinsol.get(), residual, x.get()), "KINInit");
  check(KINSetUserData(kinsol.get(), &callbacks), "KINSetUserData");
  check(KINSetLinearSolver(kinsol.get(), gmres.get(), nullptr), "KINSetLinearSolver");
  check(KINSetPreconditioner(kinsol.get(), preconditioner_setup, preconditioner_solve), "KINSetPreconditioner");
  check(KINSetFuncNormTol(kinsol.get(), o.tolerance), "KINSetFuncNormTol");
  check(KINSetScaledStepTol(kinsol.get(), 1e-14), "KINSetScaledStepTol");
  check(KINSetNumMaxIters(kinsol.get(), o.max_iterations), "KINSetNumMaxIters");
  // The preconditioner does not depend on u: set it up once per solve.
  check(KINSetMaxSetupCalls(kinsol.get(), o.max_iterations + 1), "KINSetMaxSetupCalls");
  // Difference-quotient Jacobian products are good to about sqrt(eps) of F:
  // near convergence the line search may need more tries at its beta condition.
  check(KINSetMaxBetaFails(kinsol.get(), 50), "KINSetMaxBetaFails");
  // Solve each Newton system tightly: the preconditioner is nearly the
  // tangent, so GMRES needs few iterations, and Newton keeps its quadratic rate.
  check(KINSetEtaForm(kinsol.get(), KIN_ETACONSTANT), "KINSetEtaForm");
  check(KINSetEtaConstValue(kinsol.get(), 1e-6), "KINSetEtaConstValue");
  check(KINSetPrintLevel(kinsol.get(), std::getenv("MPMVV_KINSOL_PRINT") ? 1 : 0), "KINSetPrintLevel");
  // Failures come back as the result's message, not on stderr.
  check(KINSetErrFile(kinsol.get(), nullptr), "KINSetErrFile");
  // KINSOL's default longest step is 1000 |u0| in the scaled norm, or 1 from
  // u0 = 0: one cell in the L2 norm over all nodes, far short of a load step
  // that moves many nodes a fraction of a cell. Allow 1000 cells per node.
  check(KINSetMaxNewtonStep(kinsol.get(), 1e3 * std::sqrt(double(n))), "KINSetMaxNewtonStep");
  const int flag = KINSol(kinsol.get(), x.get(), KIN_LINESEARCH, u_scale.get(), f_scale.get());
  r.converged = flag >= 0;
  // KINGetReturnFlagName names these two NONE; they say where the residual
  // could not be evaluated (a particle turned inside out, a non-finite force).
  if (flag == KIN_FIRST_SYSFUNC_ERR) {
    r.message = "the residual is not finite at the initial guess (KIN_FIRST_SYSFUNC_ERR, flag -14)";
  } else if (flag == KIN_REPTD_SYSFUNC_ERR) {
    r.message = "the residual was not finite at the trial points of repeated steps (KIN_REPTD_SYSFUNC_ERR, flag -15)";
  } else if (!r.converged) {
    char* name = KINGetReturnFlagName(flag);
    r.message = std::string(name ? name : "KINSol failed") + " (flag " + std::to_string(flag) + ")";
    free(name);
  }
  check(KINGetNumNonlinSolvIters(kinsol.get(), &r.iterations), "KINGetNumNonlinSolvIters");
  check(KINGetNumLinIters(kinsol.get(), &r.linear_iterations), "KINGetNumLinIters");
  check(KINGetNumPrecEvals(kinsol.get(), &r.preconditioner_setups), "KINGetNumPrecEvals");
  check(KINGetFuncNorm(kinsol.get(), &r.residual_norm), "KINGetFuncNorm");
  r.residual_evaluations = callbacks.evaluations;
  std::copy(NV_DATA_S(x.get()), NV_DATA_S(x.get()) + n, u.begin());
  return r;
}

}  // namespace mpmvv
