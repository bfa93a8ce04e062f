// A manufactured body force as a field of the reference position, b(X, t)
// per unit mass, and how a particle takes its share of it.
//
// A particle stands for its reference domain Omega_p: its mass is
// m_p = rho_0 V_p0, and its body force in the grid's equations is
// f_g = int_Omega_p rho_0 b S_g dV_0 (002_c3305cb8b1bc1490.txt eq. 1.64 with
// the force spread over the domain). The usual one-point rule takes b at the
// centroid, b_p = b(X_p, t), with an error of order (domain width)^2 times
// the second derivatives of b. Where the force is large against the motion it
// makes, that error is not small against the motion: in a stiff solid moved
// slowly (the stiff vortex, suites/stiff-vortex.toml) the ring's force is
// about 2,400 times its inertia, and the centroid rule's error in the net
// torque of its stress part, which is exactly zero over the ring
// (int R^2 (3 h' + R h'') dR = [R^3 h'] = 0, 000_1dbcb8acb6dddab9.txt
// eq. 2.15), spins the whole ring faster than the exact motion turns it. The
// domain rule takes the mean of b over the reference domain by the 2 x 2
// Gauss rule, exact for b cubic in each coordinate.
#pragma once

#include <cmath>
#include <cstddef>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "solver/model.hpp"

namespace mpmvv::mms {

// b(X, t) at a set of reference points fixed between calls to prepare() or
// place(). A field may keep factors of each point that do not change with time.
class ForceField {
 public:
  virtual ~ForceField() = default;
  // The field is evaluated at `count` points from now on: point index[k] is
  // (re)placed at at[k], and the others keep where they were. A split (split.hpp)
  // moves its parents and appends its halves; only those are placed again.
  virtual void place(std::size_t count, const std::vector<std::size_t>& index, const std::vector<Vec2>& at) = 0;
  // b at every point [m/s^2].
  virtual void evaluate(double t, std::vector<Vec2>& b) const = 0;
  // The bytes the field keeps for its points.
  virtual std::size_t bytes() const = 0;
  // All points placed anew.
  void prepare(const std::vector<Vec2>& points) { place(points.size(), all_indices(points.size()), points); }

  // 0, 1, ..., n - 1.
  static std::vector<std::size_t> all_indices(std::size_t n) {
    std::vector<std::size_t> index(n);
    std::iota(index.begin(), index.end(), std::size_t{0});
    return index;
  }
};

// ForceField::place for a field that keeps its points as they are.
inline void place_points(std::vector<Vec2>& points, std::size_t count, const std::vector<std::size_t>& index,
                         const std::vector<Vec2>& at) {
  points.resize(count);
  for (std::size_t k = 0; k < index.size(); ++k) points[index[k]] = at[k];
}

// Where a particle samples the field.
enum class ForceQuadrature {
  centroid,  // b_p = b(X_p, t)
  domain,    // b_p = the mean of b over the reference domain, 2 x 2 Gauss points
};

inline const char* to_string(ForceQuadrature q) { return q == ForceQuadrature::centroid ? "centroid" : "domain"; }

// The body-force stage of a manufactured scene. The reference domain of
// particle p is the parallelogram X_p + A_p [-1, 1]^2, A_p = diag(l_p) with l
// its half_size (uGIMP and CPDI: the seeded square of the particle's area,
// halved along with the particle when a CPDI domain splits) or A_p its
// turned half-vectors (solver/domain_angle.hpp); a particle without one
// (linear MPM) takes the square of its reference area, sqrt(V_p0) / 2 (in
// r-z, where V_p0 is the area's first moment about the axis,
// sqrt(V_p0 / R_p) / 2). In r-z the Gauss points are weighted by their radius,
// as the volume they stand for is.
class ManufacturedBodyForce final : public BodyForce {
 public:
  ManufacturedBodyForce(std::shared_ptr<ForceField> field, ForceQuadrature quadrature, Geometry geometry)
      : field_(std::move(field)), quadrature_(quadrature), geometry_(geometry) {}

  ForceQuadrature quadrature() const { return quadrature_; }

  void prepare(const Particles& P) override { place_particles(P, ForceField::all_indices(P.size())); }

  // Only the particles a split changed or appended are placed again: the
  // others' points, and what the field keeps for them, still hold.
  void update(const Particles& P, std::size_t previous_count, const std::vector<std::size_t>& changed) override {
    std::vector<std::size_t> particles = changed;
    for (std::size_t p = previous_count; p < P.size(); ++p) particles.push_back(p);
    place_particles(P, particles);
  }

  std::size_t bytes() const override { return field_->bytes() + bytes_held(weight_) + bytes_held(at_points_); }

  void evaluate(double t, const Particles& P, std::vector<Vec2>& b) const override {
    const std::size_t n = P.size();
    if (prepared_for_ != n) throw std::logic_error("manufactured body force: prepare() was not called for these particles");
    if (quadrature_ == ForceQuadrature::centroid) {
      field_->evaluate(t, b);
      return;
    }
    field_->evaluate(t, at_points_);
#pragma omp parallel for schedule(static)
    for (std::size_t p = 0; p < n; ++p) {
      Vec2 mean = Vec2::Zero();
      for (std::size_t k = 0; k < kPoints; ++k) mean += weight_[kPoints * p + k] * at_points_[kPoints * p + k];
      b[p] = mean;
    }
  }

 private:
  static constexpr std::size_t kPoints = 4;

  // Places the sample points of the listed particles, for a set of P.size().
  void place_particles(const Particles& P, const std::vector<std::size_t>& particles) {
    const std::size_t n = P.size(), m = particles.size();
    if (quadrature_ == ForceQuadrature::centroid) {
      std::vector<Vec2> at(m);
      for (std::size_t k = 0; k < m; ++k) at[k] = P.reference_position[particles[k]];
      field_->place(n, particles, at);
      prepared_for_ = n;
      return;
    }
    const bool axisymmetric = geometry_ == Geometry::axisymmetric;
    const bool domains = P.half_size.size() == n;
    std::vector<std::size_t> index(kPoints * m);
    std::vector<Vec2> at(kPoints * m);
    weight_.resize(kPoints * n);
    // The 2 x 2 Gauss points of [-1, 1]^2 at +-1/sqrt(3).
    const double g = 1.0 / std::sqrt(3.0);
#pragma omp parallel for schedule(static)
    for (std::size_t k = 0; k < m; ++k) {
      const std::size_t p = particles[k];
      const Vec2& X = P.reference_position[p];
      Mat2 a;
      if (domains) {
        a = P.reference_domain(p);
      } else {
        const double area = axisymmetric ? P.reference_volume[p] / X.x() : P.reference_volume[p];
        a = 0.5 * std::sqrt(area) * Mat2::Identity();
      }
      double total = 0.0;
      for (std::size_t j = 0; j < kPoints; ++j) {
        const Vec2 Y = X + g * (a * Vec2(j % 2 == 0 ? -1.0 : 1.0, j / 2 == 0 ? -1.0 : 1.0));
        index[kPoints * k + j] = kPoints * p + j;
        at[kPoints * k + j] = Y;
        weight_[kPoints * p + j] = axisymmetric ? Y.x() : 1.0;
        total += weight_[kPoints * p + j];
      }
      for (std::size_t j = 0; j < kPoints; ++j) weight_[kPoints * p + j] /= total;
    }
    field_->place(kPoints * n, index, at);
    at_points_.resize(kPoints * n);
    prepared_for_ = n;
  }
  std::shared_ptr<ForceField> field_;
  ForceQuadrature quadrature_;
  Geometry geometry_;
  std::size_t prepared_for_ = 0;          // the particle count prepare() saw
  std::vector<double> weight_;            // domain rule: per Gauss point, summing to one per particle
  mutable std::vector<Vec2> at_points_;   // domain rule: b at the Gauss points, this step
};

}  // namespace mpmvv::mms
