// A small nonlinear system F(u) = 0 solved with SUNDIALS KINSOL (Newton with a
// line search and a dense difference-quotient Jacobian). Every SUNDIALS call is
// checked and names itself when it fails; the handles are owned here.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "solver/implicit/sundials.hpp"

namespace mpmvv::analytic {

// Thrown when a SUNDIALS call fails or KINSOL cannot converge.
using SundialsError = sundials::SundialsError;

struct NonlinearSolution {
  std::vector<double> u;
  long iterations = 0;
  double residual_norm = 0.0;  // max |F(u)| at the solution
};

// Solves F(u) = 0 from `guess` until max |F| <= tolerance (KINSOL's
// function-norm tolerance, in the scaled max norm with unit scaling).
// Throws SundialsError when KINSOL cannot converge.
NonlinearSolution solve_nonlinear(const std::function<void(const std::vector<double>& u, std::vector<double>& f)>& F,
                                  std::vector<double> guess, double tolerance);

}  // namespace mpmvv::analytic
