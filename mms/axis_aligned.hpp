// Axis-aligned MMS (PROBLEMS.md section 3, after Wallstedt & Guilkey 2008 and
// Steffen et al. 2008): a smooth small-deformation motion of the unit square
// with no geometry error, which isolates the spatial and temporal order.
//   2D: u_x = A sin(pi X) sin(c pi t),  u_y = A sin(pi Y) sin(pi (2/3 + c t))
//   1D: u_x = A sin(2 pi X / L) cos(c pi t / L), u_y = 0 (a strip in uniaxial strain)
// with c = sqrt(E / rho_0). Both vanish on the boundary of the body, so roller
// walls there are exact.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

#include <Eigen/Core>

#include "force_field.hpp"
#include "jet.hpp"
#include "solver/material/neo_hookean.hpp"

namespace mpmvv::mms {

struct AxisAlignedMotion {
  double amplitude = 0.05;     // A [m]
  double wave_speed = 100.0;   // c = sqrt(E / rho_0) [m/s]
  double length = 1.0;         // L, the side of the square or the strip [m]
  bool one_dimensional = false;
  // Separable (manufactured.hpp): the sines of X and Y, and the time
  // functions T_x and T_y (the second factor of each is 0 in 1D).
  static constexpr int kSpaceFactors = 2, kTimeFactors = 2;

  template <class S>
  std::array<S, 2> space_factors(const Eigen::Matrix<S, 2, 1>& X) const {
    using std::numbers::pi;
    using std::sin;
    const S L(length);
    if (one_dimensional) return {sin(S(2.0 * pi) * X.x() / L), S(0.0)};
    return {sin(S(pi) * X.x() / L), sin(S(pi) * X.y() / L)};
  }
  template <class S>
  std::array<S, 2> time_factors(const S& t) const {
    using std::cos;
    using std::numbers::pi;
    using std::sin;
    const S c(wave_speed), L(length);
    if (one_dimensional) return {cos(c * S(pi) * t / L), S(0.0)};
    return {sin(c * S(pi) * t / L), sin(S(pi) * (S(2.0 / 3.0) + c * t / L))};
  }
  template <class S>
  MPMVV_JET_INLINE Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X, const std::array<S, 2>& space,
                                                   const std::array<S, 2>& time) const {
    const S A(amplitude);
    if (one_dimensional) return {X.x() + A * space[0] * time[0], X.y()};
    return {X.x() + A * space[0] * time[0], X.y() + A * space[1] * time[1]};
  }
  template <class S>
  Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X, const S& t) const {
    return position(X, space_factors(X), time_factors(t));
  }
  double length_scale() const { return length; }
  double time_scale() const { return length / wave_speed; }
};

// The body force of the axis-aligned motion in the neo-Hookean solid, in
// closed form. Each displacement component varies along its own axis only,
//   u_k = A sin(q X_k) T_k(t)   (2D: q = pi / L, T_x = sin(c pi t / L),
//   T_y = sin(pi (2/3 + c t / L)); 1D: q = 2 pi / L, T_x = cos(c pi t / L), u_y = 0),
// so F = diag(F_x, F_y) with F_k = 1 + A q cos(q X_k) T_k, J = F_x F_y, and the
// first Piola stress P = mu (F - F^-T) + lambda ln J F^-T is diagonal, with
//   P_kk = mu (F_k - 1 / F_k) + lambda ln J / F_k,
//   dP_kk / dX_k = F_k' (mu (1 + 1 / F_k^2) + lambda (1 - ln J) / F_k^2),
//   F_k' = -A q^2 sin(q X_k) T_k.
// The balance b = a - Div P / rho_0 with a_k = A sin(q X_k) T_k'' is then
//   b_k = A sin(q X_k) (T_k'' + q^2 T_k (mu (1 + 1 / F_k^2) + lambda (1 - ln J) / F_k^2) / rho_0).
// tests/test_manufactured.cpp shows it equals the derived force to round-off.
// A step costs one logarithm per point instead of the derived force's
// second-order jets (mpmvv-bench-forcing).
class AxisAlignedClosedFormField final : public ForceField {
 public:
  AxisAlignedClosedFormField(const AxisAlignedMotion& motion, const NeoHookean& material, double density)
      : motion_(motion), material_(material), density_(density) {}

  void place(std::size_t count, const std::vector<std::size_t>& index, const std::vector<Vec2>& at) override {
    sin_.resize(count);
    cos_.resize(count);
    const double q = wavenumber();
    for (std::size_t k = 0; k < index.size(); ++k) {
      sin_[index[k]] = Vec2(std::sin(q * at[k].x()), std::sin(q * at[k].y()));
      cos_[index[k]] = Vec2(std::cos(q * at[k].x()), std::cos(q * at[k].y()));
    }
  }

  void evaluate(double t, std::vector<Vec2>& b) const override {
    using std::numbers::pi;
    const double A = motion_.amplitude, q = wavenumber(), L = motion_.length;
    const double omega = motion_.wave_speed * pi / L;  // T_k'' = -omega^2 T_k
    const bool one_d = motion_.one_dimensional;
    const double Tx = one_d ? std::cos(omega * t) : std::sin(omega * t);
    const double Ty = one_d ? 0.0 : std::sin(pi * 2.0 / 3.0 + omega * t);
    const double lambda = material_.lambda, mu = material_.mu, rho = density_;
    const std::size_t n = sin_.size();
#pragma omp parallel for schedule(static)
    for (std::size_t p = 0; p < n; ++p) {
      const double Fx = 1.0 + A * q * cos_[p].x() * Tx, Fy = 1.0 + A * q * cos_[p].y() * Ty;
      const double log_J = std::log(Fx * Fy);
      auto component = [&](double s, double T, double F) {
        const double stiffness = mu * (1.0 + 1.0 / (F * F)) + lambda * (1.0 - log_J) / (F * F);
        return A * s * (-omega * omega * T + q * q * T * stiffness / rho);
      };
      b[p] = Vec2(component(sin_[p].x(), Tx, Fx), one_d ? 0.0 : component(sin_[p].y(), Ty, Fy));
    }
  }

  std::size_t bytes() const override { return bytes_held(sin_) + bytes_held(cos_); }

 private:
  double wavenumber() const {
    return (motion_.one_dimensional ? 2.0 : 1.0) * std::numbers::pi / motion_.length;
  }
  AxisAlignedMotion motion_;
  NeoHookean material_;
  double density_;
  std::vector<Vec2> sin_, cos_;  // sin(q X), sin(q Y) and the cosines, per point
};

}  // namespace mpmvv::mms
