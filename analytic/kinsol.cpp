#include "kinsol.hpp"

#include "solver/implicit/sundials.hpp"

#include <kinsol/kinsol.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <cmath>
#include <memory>

namespace mpmvv::analytic {

namespace {

using sundials::check;
using sundials::check_pointer;
using sundials::Context;
using sundials::KinsolDeleter;
using sundials::LinearSolverDeleter;
using sundials::MatrixDeleter;
using sundials::VectorDeleter;

struct Problem {
  const std::function<void(const std::vector<double>&, std::vector<double>&)>* F;
  std::vector<double> u, f;
};

int residual(N_Vector u, N_Vector f, void* data) {
  auto* problem = static_cast<Problem*>(data);
  const sunindextype n = NV_LENGTH_S(u);
  std::copy(NV_DATA_S(u), NV_DATA_S(u) + n, problem->u.begin());
  (*problem->F)(problem->u, problem->f);
  for (sunindextype i = 0; i < n; ++i)
    if (!std::isfinite(problem->f[std::size_t(i)])) return 1;  // recoverable: KINSOL shortens the step
  std::copy(problem->f.begin(), problem->f.end(), NV_DATA_S(f));
  return 0;
}

}  // namespace

NonlinearSolution solve_nonlinear(const std::function<void(const std::vector<double>& u, std::vector<double>& f)>& F,
                                  std::vector<double> guess, double tolerance) {
  const sunindextype n = sunindextype(guess.size());
  Context context;
  std::unique_ptr<_generic_N_Vector, VectorDeleter> u(check_pointer(N_VNew_Serial(n, context.context), "N_VNew_Serial"));
  std::unique_ptr<_generic_N_Vector, VectorDeleter> scale(check_pointer(N_VNew_Serial(n, context.context), "N_VNew_Serial"));
  std::copy(guess.begin(), guess.end(), NV_DATA_S(u.get()));
  N_VConst(1.0, scale.get());
  std::unique_ptr<_generic_SUNMatrix, MatrixDeleter> J(check_pointer(SUNDenseMatrix(n, n, context.context), "SUNDenseMatrix"));
  std::unique_ptr<_generic_SUNLinearSolver, LinearSolverDeleter> solver(
      check_pointer(SUNLinSol_Dense(u.get(), J.get(), context.context), "SUNLinSol_Dense"));
  std::unique_ptr<void, KinsolDeleter> kinsol(check_pointer(KINCreate(context.context), "KINCreate"));
  Problem problem{&F, std::vector<double>(guess.size()), std::vector<double>(guess.size())};
  check(KINInit(kinsol.get(), residual, u.get()), "KINInit");
  check(KINSetUserData(kinsol.get(), &problem), "KINSetUserData");
  check(KINSetLinearSolver(kinsol.get(), solver.get(), J.get()), "KINSetLinearSolver");
  check(KINSetFuncNormTol(kinsol.get(), tolerance), "KINSetFuncNormTol");
  check(KINSetScaledStepTol(kinsol.get(), 1e-15), "KINSetScaledStepTol");
  check(KINSetMaxSetupCalls(kinsol.get(), 1), "KINSetMaxSetupCalls");  // a fresh Jacobian every iteration
  check(KINSetNumMaxIters(kinsol.get(), 200), "KINSetNumMaxIters");
  check(KINSetPrintLevel(kinsol.get(), 0), "KINSetPrintLevel");
  check(KINSol(kinsol.get(), u.get(), KIN_LINESEARCH, scale.get(), scale.get()), "KINSol");

  NonlinearSolution s;
  s.u.assign(NV_DATA_S(u.get()), NV_DATA_S(u.get()) + n);
  check(KINGetNumNonlinSolvIters(kinsol.get(), &s.iterations), "KINGetNumNonlinSolvIters");
  F(s.u, problem.f);
  for (double v : problem.f) s.residual_norm = std::max(s.residual_norm, std::abs(v));
  return s;
}

}  // namespace mpmvv::analytic
