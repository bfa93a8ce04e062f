// Ring MMS ("generalized vortex"), PROBLEMS.md section 1 and
// 000_1dbcb8acb6dddab9.txt chapter 2. Every material circle of the ring
// R_i <= R <= R_o turns rigidly by
//   alpha(R, t) = g(t) h(R),   x = R [cos(Theta + alpha), sin(Theta + alpha)]   (eq. 2.1)
// with h(R) = (1 - s^2)^2, s = (R - R_m) / w, R_m = (R_i + R_o)/2, w = (R_o - R_i)/2;
// for the report's ring (0.75, 1.25) this is 1 - 32 (R-1)^2 + 256 (R-1)^4.
// h = h' = 0 at both rims, so the rims are traction-free.
//
// One parameter set feeds the motion, the exact fields and the body force, so
// they cannot drift apart.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <Eigen/Core>

#include <stdexcept>
#include <vector>

#include "force_field.hpp"
#include "jet.hpp"
#include "solver/lane_math.hpp"
#include "solver/material/neo_hookean.hpp"
#include "solver/model.hpp"
#include "solver/tensor.hpp"

namespace mpmvv::mms {

enum class RingTimeFunction {
  cosine,  // g = (A/2)(1 - cos 2 pi t): the Sandia report; starts at rest
  sine,    // g = A sin(pi t): the MMS paper; starts with v = R g'(0) h(R) e_theta
};

struct RingParameters {
  double inner_radius = 0.75;   // R_i [m]
  double outer_radius = 1.25;   // R_o [m]
  double amplitude = 0.5;       // A [rad]
  RingTimeFunction time_function = RingTimeFunction::cosine;
  double lambda = 577.0;        // [Pa], report eq. 2.2
  double mu = 385.0;            // [Pa]
  double density = 1000.0;      // rho_0 [kg/m^3]
};

// The motion alone, generic over the scalar, for the generator
// (manufactured.hpp): x = Q(alpha) X with alpha = g(t) h(|X|), the rotation
// form of eq. 2.1 (it avoids atan2). Its factor of X alone is h(|X|), of t
// alone g(t) (a separable motion, manufactured.hpp).
struct RingMotion {
  RingParameters p;
  static constexpr int kSpaceFactors = 1, kTimeFactors = 1;

  template <class S>
  S g(const S& t) const {
    using std::cos;
    using std::numbers::pi;
    using std::sin;
    return p.time_function == RingTimeFunction::cosine ? S(0.5 * p.amplitude) * (S(1.0) - cos(S(2.0 * pi) * t))
                                                       : S(p.amplitude) * sin(S(pi) * t);
  }
  template <class S>
  S h(const S& R) const {
    const S s = (R - S(0.5 * (p.inner_radius + p.outer_radius))) / S(0.5 * (p.outer_radius - p.inner_radius));
    const S q = S(1.0) - s * s;
    return q * q;
  }
  template <class S>
  std::array<S, 1> space_factors(const Eigen::Matrix<S, 2, 1>& X) const {
    using std::sqrt;
    return {h(S(sqrt(X.x() * X.x() + X.y() * X.y())))};
  }
  template <class S>
  std::array<S, 1> time_factors(const S& t) const {
    return {g(t)};
  }
  template <class S>
  MPMVV_JET_INLINE Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X, const std::array<S, 1>& space,
                                                   const std::array<S, 1>& time) const {
    const S alpha = time[0] * space[0];
    const auto turn = sin_cos(alpha);
    const S c = turn.cos, s = turn.sin;
    return {c * X.x() - s * X.y(), s * X.x() + c * X.y()};
  }
  template <class S>
  Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X, const S& t) const {
    return position(X, space_factors(X), time_factors(t));
  }
  double length_scale() const { return p.outer_radius - p.inner_radius; }
  double time_scale() const { return 1.0; }
};

// Exact fields at one material point and time.
struct RingState {
  Vec2 position;        // x
  Vec2 displacement;    // u = x - X
  Vec2 velocity;        // v
  Vec2 acceleration;    // a
  Mat2 deformation_gradient;  // F
  Mat2 cauchy_stress;   // sigma
  Mat2 first_piola;     // P = J sigma F^-T
  double angle;         // alpha
};

class RingMms {
 public:
  explicit RingMms(const RingParameters& p) : p_(p), material_{p.lambda, p.mu} {}

  const RingParameters& parameters() const { return p_; }
  const NeoHookean& material() const { return material_; }

  // Time function g and its first two derivatives.
  double g(double t) const {
    using std::numbers::pi;
    return p_.time_function == RingTimeFunction::cosine ? 0.5 * p_.amplitude * (1.0 - std::cos(2.0 * pi * t))
                                                        : p_.amplitude * std::sin(pi * t);
  }
  double g_dot(double t) const {
    using std::numbers::pi;
    return p_.time_function == RingTimeFunction::cosine ? p_.amplitude * pi * std::sin(2.0 * pi * t)
                                                        : p_.amplitude * pi * std::cos(pi * t);
  }
  double g_ddot(double t) const {
    using std::numbers::pi;
    return p_.time_function == RingTimeFunction::cosine ? 2.0 * p_.amplitude * pi * pi * std::cos(2.0 * pi * t)
                                                        : -p_.amplitude * pi * pi * std::sin(pi * t);
  }

  // Radial profile h and its first two derivatives.
  double h(double R) const {
    const double s = scaled(R);
    return (1.0 - s * s) * (1.0 - s * s);
  }
  double h_prime(double R) const {
    const double s = scaled(R);
    return -4.0 * s * (1.0 - s * s) / half_width();
  }
  double h_second(double R) const {
    const double s = scaled(R);
    return -4.0 * (1.0 - 3.0 * s * s) / (half_width() * half_width());
  }

  double angle(double R, double t) const { return g(t) * h(R); }

  bool contains(const Vec2& X) const {
    const double R = X.norm();
    return R >= p_.inner_radius && R <= p_.outer_radius;
  }

  // Exact current position of the material point X.
  Vec2 position(const Vec2& X, double t) const {
    const double R = X.norm();
    const double theta = std::atan2(X.y(), X.x()) + angle(R, t);
    return {R * std::cos(theta), R * std::sin(theta)};
  }

  // All exact fields at reference point X and time t.
  RingState state(const Vec2& X, double t) const {
    const double R = X.norm();
    const double Theta = std::atan2(X.y(), X.x());
    const double alpha = angle(R, t);
    const double theta = Theta + alpha;
    const Vec2 e_r(std::cos(theta), std::sin(theta)), e_t(-std::sin(theta), std::cos(theta));
    const Vec2 E_R(std::cos(Theta), std::sin(Theta)), E_T(-std::sin(Theta), std::cos(Theta));
    const double alpha_t = g_dot(t) * h(R), alpha_tt = g_ddot(t) * h(R), alpha_R = g(t) * h_prime(R);
    RingState s;
    s.angle = alpha;
    s.position = R * e_r;
    s.displacement = s.position - X;
    s.velocity = R * alpha_t * e_t;
    s.acceleration = -R * alpha_t * alpha_t * e_r + R * alpha_tt * e_t;
    // dx/dR = e_r + R alpha_R e_theta and (1/R) dx/dTheta = e_theta.
    s.deformation_gradient = (e_r + R * alpha_R * e_t) * E_R.transpose() + e_t * E_T.transpose();
    s.cauchy_stress = material_.cauchy_stress(s.deformation_gradient);
    const double J = determinant(s.deformation_gradient);
    s.first_piola = J * s.cauchy_stress * inverse(s.deformation_gradient).transpose();
    return s;
  }

  // The factors of the motion: the radial profile at a material radius and the
  // time function at a time. The body force below is assembled from them, so a
  // caller that keeps the radial factors of each particle evaluates exactly the
  // same expression.
  struct Radial {
    double R, h, h_prime, h_second;
  };
  struct Temporal {
    double g, g_dot, g_ddot;
  };
  Radial radial(double R) const { return {R, h(R), h_prime(R), h_second(R)}; }
  Temporal temporal(double t) const { return {g(t), g_dot(t), g_ddot(t)}; }

  // Body force per unit mass, eqs. 2.14-2.15, as components (b_r, b_theta) in
  // the current polar basis at theta = Theta + alpha(R, t), R the reference
  // radius. lambda drops out because the motion keeps J = 1.
  Vec2 polar_body_force(const Radial& r, const Temporal& q) const {
    const double nu = p_.mu / p_.density;
    const double rate = q.g_dot * r.h, shear = r.h_prime * q.g;
    return {-r.R * rate * rate + nu * r.R * shear * shear,
            r.R * q.g_ddot * r.h - nu * (3.0 * r.h_prime + r.R * r.h_second) * q.g};
  }

  // The same force in Cartesian components: rotated by theta, where the
  // reference angle enters through (cos Theta, sin Theta).
  Vec2 body_force(const Radial& r, double cos_Theta, double sin_Theta, const Temporal& q) const {
    const double alpha = turn(r, q);
    return body_force(r, cos_Theta, sin_Theta, q, std::cos(alpha), std::sin(alpha));
  }
  // The angle alpha = g h(R) a point has turned through, and the force given
  // its cosine and sine (a caller that has them for many points at once).
  static double turn(double h, const Temporal& q) { return q.g * h; }
  static double turn(const Radial& r, const Temporal& q) { return turn(r.h, q); }
  Vec2 body_force(const Radial& r, double cos_Theta, double sin_Theta, const Temporal& q, double cos_alpha,
                  double sin_alpha) const {
    const Vec2 b = polar_body_force(r, q);
    const double c = cos_Theta * cos_alpha - sin_Theta * sin_alpha;  // cos theta
    const double s = sin_Theta * cos_alpha + cos_Theta * sin_alpha;  // sin theta
    return {b.x() * c - b.y() * s, b.x() * s + b.y() * c};
  }

  Vec2 body_force(const Vec2& X, double t) const {
    const double R = X.norm();
    return body_force(radial(R), X.x() / R, X.y() / R, temporal(t));
  }

 private:
  double half_width() const { return 0.5 * (p_.outer_radius - p_.inner_radius); }
  double scaled(double R) const { return (R - 0.5 * (p_.inner_radius + p_.outer_radius)) / half_width(); }

  RingParameters p_;
  NeoHookean material_;
};

// The closed form as a force field (force_field.hpp), for the neo-Hookean
// ring. It keeps each point's reference radius and direction (24 bytes a
// point) and forms the radial factors h, h' and h'' from the radius at every
// evaluation, by the same expressions a cache of them would hold (48 bytes a
// point): three divisions and the profile's polynomials a point and step.
// A step then costs those, one time-function evaluation and one sin/cos pair
// per point. tests/test_manufactured.cpp shows it equals the derived force to
// round-off.
class RingClosedFormField final : public ForceField {
 public:
  explicit RingClosedFormField(const RingMms& mms) : mms_(mms) {}

  void place(std::size_t count, const std::vector<std::size_t>& index, const std::vector<Vec2>& at) override {
    radius_.resize(count);
    direction_.resize(count);
    const std::size_t n = index.size();
#pragma omp parallel for schedule(static)
    for (std::size_t k = 0; k < n; ++k) {
      const Vec2& X = at[k];
      const double R = X.norm();
      radius_[index[k]] = R;
      direction_[index[k]] = X / R;
    }
  }

  // The turned angles' sines and cosines a block of points at a time from
  // the lanes (solver/lane_math.hpp; libm's scalar sincos was more than half of
  // this function), within one unit in the last place: the force differs from
  // the scalar formula above in its last bits only.
  void evaluate(double t, std::vector<Vec2>& b) const override {
    constexpr std::size_t kBlock = 256;
    const std::size_t n = radius_.size();
    const RingMms::Temporal q = mms_.temporal(t);
#pragma omp parallel for schedule(static)
    for (std::size_t first = 0; first < n; first += kBlock) {
      const std::size_t count = std::min(kBlock, n - first);
      const double* R = radius_.data() + first;
      // Array by array, so that the divisions go two or more to an instruction
      // (RingMms::radial into an array of Radial is not vectorised: 12 more
      // instructions a particle-step, callgrind).
      double h[kBlock], h_prime[kBlock], h_second[kBlock], alpha[kBlock], cos_alpha[kBlock], sin_alpha[kBlock];
      for (std::size_t k = 0; k < count; ++k) {
        h[k] = mms_.h(R[k]);
        h_prime[k] = mms_.h_prime(R[k]);
        h_second[k] = mms_.h_second(R[k]);
      }
      for (std::size_t k = 0; k < count; ++k) alpha[k] = RingMms::turn(h[k], q);
      lane_sincos(count, alpha, sin_alpha, cos_alpha);
      for (std::size_t k = 0; k < count; ++k) {
        const Vec2& d = direction_[first + k];
        b[first + k] = mms_.body_force({R[k], h[k], h_prime[k], h_second[k]}, d.x(), d.y(), q, cos_alpha[k],
                                       sin_alpha[k]);
      }
    }
  }

  std::size_t bytes() const override { return bytes_held(radius_) + bytes_held(direction_); }

 private:
  RingMms mms_;
  std::vector<double> radius_;    // |X|
  std::vector<Vec2> direction_;   // X / |X|: (cos Theta, sin Theta)
};

}  // namespace mpmvv::mms
