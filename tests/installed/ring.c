/* The ring's body force from C through the installed mpmvv_mms.h: at three
 * points, printed to the last bit, then at N points around the ring (argv[1],
 * default 10^6), timed. tests/installed_tree.py compiles and checks it. */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "mpmvv_mms.h"

static double seconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char** argv) {
  const size_t n = argc > 1 ? (size_t)atol(argv[1]) : 1000000;
  const char* settings[] = {"amplitude=0.5"};
  mpmvv_mms_solution* ring = mpmvv_mms_create("ring", 1, settings);
  if (!ring) {
    fprintf(stderr, "ring.c: %s\n", mpmvv_mms_last_error());
    return 1;
  }
  const double X[6] = {1.0, 0.0, 0.8, 0.5, -0.3, -0.9};
  double b[6];
  if (mpmvv_mms_body_force(ring, 0.25, 3, X, b) != 0) {
    fprintf(stderr, "ring.c: %s\n", mpmvv_mms_last_error());
    return 1;
  }
  for (int p = 0; p < 3; ++p) printf("b %.17g %.17g %.17g %.17g\n", X[2 * p], X[2 * p + 1], b[2 * p], b[2 * p + 1]);
  double* points = malloc(2 * n * sizeof(double));
  double* forces = malloc(2 * n * sizeof(double));
  for (size_t p = 0; p < n; ++p) {
    const double r = 0.75 + 0.5 * ((double)p + 0.5) / (double)n, angle = 2.399963229728653 * (double)p;
    points[2 * p] = r * cos(angle);
    points[2 * p + 1] = r * sin(angle);
  }
  const double start = seconds();
  const int status = mpmvv_mms_body_force(ring, 0.25, n, points, forces);
  const double wall = seconds() - start;
  printf("points %zu status %d seconds %.6g ns_per_point %.4g\n", n, status, wall, 1e9 * wall / (double)n);
  free(points);
  free(forces);
  mpmvv_mms_destroy(ring);
  return status;
}
