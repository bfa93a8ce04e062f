/* The manufactured and exact solutions of mpmvv for other codes: a plain C
 * interface (C, C++, and Fortran through iso_c_binding) to the same solutions
 * `mpmvv mms` lists and the scenes run, by name with the scenes' parameters.
 * A solution evaluates, for arrays of reference points X (R, Z in r-z) at a
 * time t, the exact displacement, velocity, acceleration, deformation
 * gradient, Cauchy and first Piola stresses and the manufactured body force
 * b = a - Div P / rho_0 (per unit mass; zero for a solution without one).
 *
 * Arrays are flat and row-major: a vector of point p at [2p], [2p + 1]; a 2 x 2
 * tensor at [4p + 2i + j] for its (i, j) entry; the out-of-plane component
 * (zz in plane strain, theta-theta in r-z) one double per point.
 *
 * CMake: find_package(mpmvv) and target_link_libraries(app PRIVATE mpmvv::mms).
 * Otherwise: -I<prefix>/include -L<prefix>/lib -lmpmvv-mms.
 */
#ifndef MPMVV_MMS_H
#define MPMVV_MMS_H

#include <stddef.h>

#if defined(__GNUC__)
#define MPMVV_MMS_API __attribute__((visibility("default")))
#else
#define MPMVV_MMS_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

typedef struct mpmvv_mms_solution mpmvv_mms_solution;

/* The solutions by index 0 .. count - 1: name and one-line summary. NULL past the end. */
MPMVV_MMS_API int mpmvv_mms_count(void);
MPMVV_MMS_API const char* mpmvv_mms_name(int index);
MPMVV_MMS_API const char* mpmvv_mms_summary(int index);
/* 1 for a solution moved by a manufactured body force, 0 for an exact solution without one. */
MPMVV_MMS_API int mpmvv_mms_manufactured(int index);

/* A solution's parameters (the keys of its scene that set the solution, not
 * the run): how many, and each one's name, default value as text, and meaning
 * with its unit. -1 and NULLs for an unknown name or index. */
MPMVV_MMS_API int mpmvv_mms_parameter_count(const char* name);
MPMVV_MMS_API int mpmvv_mms_parameter(const char* name, int index, const char** key, const char** default_value,
                        const char** meaning);

/* A solution object holds the points its body force was last placed at: use
 * one per thread for concurrent calls (each call itself runs over the
 * library's OpenMP threads). */

/* The solution `name` with `count` settings "key=value" (as `mpmvv mms eval
 * --set`); NULL when a name, key or value is refused, with the reason in
 * mpmvv_mms_last_error(). Free it with mpmvv_mms_destroy. */
MPMVV_MMS_API mpmvv_mms_solution* mpmvv_mms_create(const char* name, int count, const char* const* settings);
MPMVV_MMS_API void mpmvv_mms_destroy(mpmvv_mms_solution* solution);
/* The calling thread's last error message ("" after a success). */
MPMVV_MMS_API const char* mpmvv_mms_last_error(void);

/* 1 in r-z (X = (R, Z), the hoop stretch F_33 = r / R), 0 in plane strain. */
MPMVV_MMS_API int mpmvv_mms_axisymmetric(const mpmvv_mms_solution* solution);
/* rho_0 [kg/m^3]. */
MPMVV_MMS_API double mpmvv_mms_density(const mpmvv_mms_solution* solution);
/* 1 when X lies in the solution's body, 0 outside. */
MPMVV_MMS_API int mpmvv_mms_contains(const mpmvv_mms_solution* solution, double x, double y);

/* Where to write: any member may be NULL and is then not evaluated. */
typedef struct mpmvv_mms_fields {
  double* position;          /* x, 2 per point [m] */
  double* displacement;      /* u = x - X, 2 per point [m] */
  double* velocity;          /* 2 per point [m/s] */
  double* acceleration;      /* 2 per point [m/s^2] */
  double* F;                 /* in-plane deformation gradient, 4 per point */
  double* F33;               /* F_33, 1 per point */
  double* cauchy_stress;     /* in-plane sigma, 4 per point [Pa] */
  double* cauchy_stress_33;  /* sigma_zz or sigma_theta, 1 per point [Pa] */
  double* first_piola;       /* in-plane P = J sigma F^-T, 4 per point [Pa] */
  double* body_force;        /* b, 2 per point [m/s^2] */
} mpmvv_mms_fields;

/* The fields at the n reference points X (2 n doubles) at time t. 0 on
 * success; -1 with mpmvv_mms_last_error() for a point outside the body or,
 * in r-z, on the axis (nothing is written past the points before it). */
MPMVV_MMS_API int mpmvv_mms_evaluate(const mpmvv_mms_solution* solution, double t, size_t n, const double* X,
                       mpmvv_mms_fields* out);
/* The body force alone at the n points, the fastest path (the closed form or
 * the derived force the scene's body_force key chooses, over threads). 0 on
 * success, -1 as above. */
MPMVV_MMS_API int mpmvv_mms_body_force(const mpmvv_mms_solution* solution, double t, size_t n, const double* X, double* b);

#ifdef __cplusplus
}
#endif

#endif
