#include "tracer_interpolation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include <Eigen/Dense>
#include <fmt/format.h>

namespace mpmvv::app {

namespace {

// The particles' reference positions in square buckets of side `side`.
class Buckets {
 public:
  Buckets(const std::vector<Vec2>& X, double side) : X_(X), side_(side) {
    for (std::size_t p = 0; p < X.size(); ++p) cells_[key(cell(X[p].x()), cell(X[p].y()))].push_back(p);
  }
  // The particles within `radius` of `at`.
  void within(const Vec2& at, double radius, std::vector<std::size_t>& out) const {
    out.clear();
    const std::int64_t i0 = cell(at.x() - radius), i1 = cell(at.x() + radius);
    const std::int64_t j0 = cell(at.y() - radius), j1 = cell(at.y() + radius);
    for (std::int64_t i = i0; i <= i1; ++i)
      for (std::int64_t j = j0; j <= j1; ++j) {
        const auto it = cells_.find(key(i, j));
        if (it == cells_.end()) continue;
        for (std::size_t p : it->second)
          if ((X_[p] - at).norm() <= radius) out.push_back(p);
      }
  }

 private:
  std::int64_t cell(double v) const { return std::int64_t(std::floor(v / side_)); }
  static std::uint64_t key(std::int64_t i, std::int64_t j) {
    return (std::uint64_t(i) << 32) ^ (std::uint64_t(j) & 0xffffffffu);
  }
  const std::vector<Vec2>& X_;
  double side_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
};

// The search stops at this many particle spacings: a tracer farther from
// kTracerNeighbours particles is not inside the particles' body.
constexpr double kFarthestSpacings = 8.0;
// The kernel reaches this much past the farthest neighbour, so that it weighs something.
constexpr double kKernelReach = 1.1;

}  // namespace

const char* tracer_interpolation_description() {
  return "interpolated by mpmvv from the particles (the program wrote no tracer_position): x - X fitted in the "
         "reference configuration by moving least squares, quadratic basis, over the 24 nearest particles "
         "(tracer_interpolation.hpp)";
}

std::vector<Vec2> interpolated_tracers(const std::vector<Vec2>& X, const std::vector<Vec2>& x,
                                       const std::vector<double>& V0, const std::vector<Vec2>& tracer_X) {
  std::vector<double> volumes;
  for (double v : V0)
    if (v > 0.0 && std::isfinite(v)) volumes.push_back(v);
  if (volumes.size() < kTracerNeighbours)
    throw TracerInterpolationError(fmt::format("{} particles with a positive reference volume: {} are needed to "
                                               "place the tracers", volumes.size(), kTracerNeighbours));
  std::nth_element(volumes.begin(), volumes.begin() + volumes.size() / 2, volumes.end());
  const double spacing = std::sqrt(volumes[volumes.size() / 2]);
  const Buckets buckets(X, 2.0 * spacing);
  std::vector<Vec2> out;
  out.reserve(tracer_X.size());
  std::vector<std::size_t> near;
  std::vector<std::pair<double, std::size_t>> by_distance;
  for (std::size_t t = 0; t < tracer_X.size(); ++t) {
    const Vec2& at = tracer_X[t];
    // Widen the search until it holds the nearest kTracerNeighbours.
    double radius = 2.0 * spacing;
    for (buckets.within(at, radius, near); near.size() < kTracerNeighbours && radius < kFarthestSpacings * spacing;
         buckets.within(at, radius, near))
      radius = std::min(2.0 * radius, kFarthestSpacings * spacing);
    if (near.size() < kTracerNeighbours)
      throw TracerInterpolationError(fmt::format(
          "tracer {} at X = ({:.6g}, {:.6g}): {} particles within {:.3g} m ({:g} particle spacings of {:.3g} m); "
          "{} are needed to place it: the particles do not cover the body there",
          t, at.x(), at.y(), near.size(), radius, kFarthestSpacings, spacing, kTracerNeighbours));
    by_distance.clear();
    for (std::size_t p : near) by_distance.emplace_back((X[p] - at).norm(), p);
    std::nth_element(by_distance.begin(), by_distance.begin() + (kTracerNeighbours - 1), by_distance.end());
    const double rho = kKernelReach * by_distance[kTracerNeighbours - 1].first;
    // The weighted quadratic fit about `at`, in units of rho (conditioning).
    Eigen::Matrix<double, kTracerNeighbours, 6> A;
    Eigen::Matrix<double, kTracerNeighbours, 2> b;
    for (std::size_t i = 0; i < kTracerNeighbours; ++i) {
      const std::size_t p = by_distance[i].second;
      const Vec2 d = (X[p] - at) / rho;
      const double q = 1.0 - d.squaredNorm();
      const double w = q * q;  // (1 - (r / rho)^2)^2 > 0 inside the kernel
      const double sw = std::sqrt(w);
      A.row(Eigen::Index(i)) << sw, sw * d.x(), sw * d.y(), sw * d.x() * d.x(), sw * d.x() * d.y(), sw * d.y() * d.y();
      b.row(Eigen::Index(i)) = sw * (x[p] - X[p]).transpose();
    }
    const Eigen::ColPivHouseholderQR<decltype(A)> qr(A);
    if (qr.rank() < 6)
      throw TracerInterpolationError(fmt::format(
          "tracer {} at X = ({:.6g}, {:.6g}): its {} nearest particles lie on a line or a conic (rank {} of 6); "
          "no quadratic fit places it", t, at.x(), at.y(), kTracerNeighbours, qr.rank()));
    const Eigen::Matrix<double, 6, 2> c = qr.solve(b);
    out.push_back(at + c.row(0).transpose());
  }
  return out;
}

}  // namespace mpmvv::app
