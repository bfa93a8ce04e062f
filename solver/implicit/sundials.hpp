// Owned SUNDIALS handles and the check every SUNDIALS call goes through: a
// failing call throws SundialsError naming itself and its flag.
#pragma once

#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>
#include <kinsol/kinsol.h>

#include <memory>
#include <stdexcept>
#include <string>

namespace mpmvv::sundials {

class SundialsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline void check(int flag, const char* call) {
  if (flag < 0) throw SundialsError(std::string("SUNDIALS ") + call + " failed with flag " + std::to_string(flag));
}

template <class T>
T* check_pointer(T* p, const char* call) {
  if (!p) throw SundialsError(std::string("SUNDIALS ") + call + " returned no object");
  return p;
}

struct Context {
  SUNContext context = nullptr;
  Context() { check(SUNContext_Create(nullptr, &context), "SUNContext_Create"); }
  ~Context() { SUNContext_Free(&context); }
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
};

struct VectorDeleter {
  void operator()(_generic_N_Vector* v) const { N_VDestroy(v); }
};
struct MatrixDeleter {
  void operator()(_generic_SUNMatrix* m) const { SUNMatDestroy(m); }
};
struct LinearSolverDeleter {
  void operator()(_generic_SUNLinearSolver* s) const { SUNLinSolFree(s); }
};
struct KinsolDeleter {
  void operator()(void* k) const { KINFree(&k); }
};

using Vector = std::unique_ptr<_generic_N_Vector, VectorDeleter>;
using Matrix = std::unique_ptr<_generic_SUNMatrix, MatrixDeleter>;
using LinearSolver = std::unique_ptr<_generic_SUNLinearSolver, LinearSolverDeleter>;
using Kinsol = std::unique_ptr<void, KinsolDeleter>;

inline Vector serial_vector(sunindextype n, SUNContext context) {
  return Vector(check_pointer(N_VNew_Serial(n, context), "N_VNew_Serial"));
}

}  // namespace mpmvv::sundials
