// The same from C++ through find_package(mpmvv) and mpmvv::mms.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <mpmvv_mms.h>

int main(int argc, char** argv) {
  const std::size_t n = argc > 1 ? std::size_t(std::atol(argv[1])) : 1000000;
  const char* settings[] = {"amplitude=0.5"};
  mpmvv_mms_solution* ring = mpmvv_mms_create("ring", 1, settings);
  if (!ring) {
    std::fprintf(stderr, "ring.cpp: %s\n", mpmvv_mms_last_error());
    return 1;
  }
  const double X[6] = {1.0, 0.0, 0.8, 0.5, -0.3, -0.9};
  double b[6];
  if (mpmvv_mms_body_force(ring, 0.25, 3, X, b) != 0) return 1;
  for (int p = 0; p < 3; ++p)
    std::printf("b %.17g %.17g %.17g %.17g\n", X[2 * p], X[2 * p + 1], b[2 * p], b[2 * p + 1]);
  std::vector<double> points(2 * n), forces(2 * n);
  for (std::size_t p = 0; p < n; ++p) {
    const double r = 0.75 + 0.5 * (double(p) + 0.5) / double(n), angle = 2.399963229728653 * double(p);
    points[2 * p] = r * std::cos(angle);
    points[2 * p + 1] = r * std::sin(angle);
  }
  const auto start = std::chrono::steady_clock::now();
  const int status = mpmvv_mms_body_force(ring, 0.25, n, points.data(), forces.data());
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("points %zu status %d seconds %.6g ns_per_point %.4g\n", n, status, wall, 1e9 * wall / double(n));
  mpmvv_mms_destroy(ring);
  return status;
}
