// A manufactured solution is one definition: a motion x = phi(X, t), written
// once and generic over its scalar type, and a material. Everything else is
// derived here:
//   F = dphi/dX and dF/dX      forward-mode AD, X a second-order jet
//   v, a = dphi/dt, d2phi/dt2  forward-mode AD, t a second-order jet
//   sigma, P = J sigma F^-T     the material, with jets carrying dP/dX
//   b = a - Div P / rho_0       balance of momentum solved for the force
// in plane strain (Cartesian X = (X, Y)) or in r-z (X = (R, Z), hoop stretch
// F_33 = r / R, and the geometric terms of the divergence in cylindrical
// coordinates:
//   (Div P)_r = dP_rR/dR + dP_rZ/dZ + (P_rR - P_thetatheta) / R,
//   (Div P)_z = dP_zR/dR + dP_zZ/dZ + P_zR / R).
//
// A Motion provides
//   template <class S> Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X, const S& t) const;
//   double length_scale() const;  double time_scale() const;   (for finite-difference checks)
// and may provide displacement(X, t) = x - X in the same form, for the checks
// of a motion whose displacement is tiny beside X (a steel bar: u / X ~ 1e-4),
// where differences of positions would lose the displacement to round-off.
// A Material provides stress(F, F_33) generic over the scalar (solver/material/).
//
// A separable Motion writes its position as a function of factors of X alone
// and factors of t alone,
//   static constexpr int kSpaceFactors, kTimeFactors;
//   template <class S> std::array<S, kSpaceFactors> space_factors(const Eigen::Matrix<S, 2, 1>& X) const;
//   template <class S> std::array<S, kTimeFactors> time_factors(const S& t) const;
//   template <class S> Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X,
//       const std::array<S, kSpaceFactors>&, const std::array<S, kTimeFactors>&) const;
// with position(X, t) = position(X, space_factors(X), time_factors(t)). A
// particle's factors of X do not change along its path: the derived force
// keeps them, with their derivatives along X, and forms the time factors once
// a step (factored_force.hpp); both give position(X, t)'s jets to the bit.
// The three-argument position is declared MPMVV_JET_INLINE (jet.hpp): the
// derived force runs it on four points in vector registers, which a call
// would pass through memory, and GCC does not inline it there by itself.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <limits>
#include <vector>

#include "jet.hpp"
#include "jet_lanes.hpp"
#include "solver/geometry.hpp"
#include "solver/material/stress.hpp"
#include "solver/tensor.hpp"

namespace mpmvv::mms {


// Everything the exact solution says at one material point and time.
struct ExactFields {
  Vec2 position, displacement, velocity, acceleration;
  Mat2 deformation_gradient;  // in-plane block of F
  double hoop_stretch;        // F_33: 1 in plane strain, r / R in r-z
  double J;
  Mat2 cauchy_stress;         // in-plane block of sigma
  double cauchy_stress_33;    // sigma_zz (plane strain) or sigma_theta (r-z)
  Mat2 first_piola;           // in-plane block of P = J sigma F^-T
  double first_piola_33;
  Vec2 body_force;            // b = a - Div P / rho_0
};

template <class Motion>
concept SeparableMotion = requires(const Motion& m, const Vec2& X) {
  { m.position(X, m.space_factors(X), m.time_factors(0.0)) } -> std::same_as<Vec2>;
  Motion::kSpaceFactors;
  Motion::kTimeFactors;
};

// How many factors of each kind a motion has (none where it is not separable).
template <class Motion>
struct FactorCounts {
  static constexpr int space = 0, time = 0;
};
template <SeparableMotion Motion>
struct FactorCounts<Motion> {
  static constexpr int space = Motion::kSpaceFactors, time = Motion::kTimeFactors;
};

template <class Motion, class Material>
class Manufactured {
  using Jet1 = Jet<double, 1>;
  using Jet2 = Jet<double, 2>;
  using TimeJet = Jet<Jet1, 1>;   // t with first and second derivative
  using SpaceJet = Jet<Jet2, 2>;  // X with gradient and Hessian

 public:
  // The jets over another innermost scalar B (four lanes: jet_lanes.hpp).
  template <class B>
  using TimeJetOf = Jet<Jet<B, 1>, 1>;
  template <class B>
  using SpaceJetOf = Jet<Jet<B, 2>, 2>;
  template <class B>
  using Vec2Of = Eigen::Matrix<B, 2, 1>;

  Manufactured(Motion motion, Material material, double density, Geometry geometry)
      : motion_(std::move(motion)), material_(material), density_(density), geometry_(geometry) {}

  const Motion& motion() const { return motion_; }
  const Material& material() const { return material_; }
  double density() const { return density_; }
  Geometry geometry() const { return geometry_; }

  Vec2 position(const Vec2& X, double t) const { return motion_.position(X, t); }
  // F_33 at X of the point now at x: r / R in r-z, 1 in plane strain.
  double hoop_stretch(const Vec2& x, const Vec2& X) const {
    return geometry_ == Geometry::axisymmetric ? x.x() / X.x() : 1.0;
  }
  Vec2 displacement(const Vec2& X, double t) const {
    if constexpr (requires { motion_.displacement(X, t); }) return motion_.displacement(X, t);
    else return motion_.position(X, t) - X;
  }

  ExactFields fields(const Vec2& X, double t) const {
    ExactFields f;
    const Temporal time = temporal(X, t);
    f.position = time.position;
    f.displacement = time.position - X;
    f.velocity = time.velocity;
    f.acceleration = time.acceleration;
    const Spatial space = spatial(X, t);
    f.deformation_gradient = value(space.F);
    f.hoop_stretch = space.F33.v;
    f.J = determinant(f.deformation_gradient) * f.hoop_stretch;
    f.cauchy_stress = value(space.sigma.in_plane);
    f.cauchy_stress_33 = space.sigma.out_of_plane.v;
    f.first_piola = value(space.P);
    f.first_piola_33 = space.P33.v;
    f.body_force = f.acceleration - divergence(space, X) / density_;
    return f;
  }

  Vec2 body_force(const Vec2& X, double t) const {
    return temporal(X, t).acceleration - divergence(spatial(X, t), X) / density_;
  }

  // A separable motion's factors of X at one point, each with its gradient
  // and Hessian along X; and its factors of t, in the jet of t (for the
  // acceleration) and as constants in the jet of X (for F and dF/dX).
  template <class B>
  using SpaceFactorsOf = std::array<SpaceJetOf<B>, FactorCounts<Motion>::space>;
  template <class B>
  struct TimeFactorsOf {
    std::array<TimeJetOf<B>, FactorCounts<Motion>::time> in_time;
    std::array<SpaceJetOf<B>, FactorCounts<Motion>::time> in_space;
  };
  using SpaceFactors = SpaceFactorsOf<double>;
  using TimeFactors = TimeFactorsOf<double>;
  SpaceFactors space_factors(const Vec2& X) const
    requires SeparableMotion<Motion>
  {
    return motion_.space_factors(space_variables(X));
  }
  TimeFactors time_factors(double t) const
    requires SeparableMotion<Motion>
  {
    return {motion_.time_factors(time_variable(t)), motion_.time_factors(SpaceJet(t))};
  }
  // body_force(X, t) from the point's factors and the time's: the same jets,
  // to the bit for B = double. The jet of t takes the factors of X as
  // constants: the value part of every jet is the plain evaluation, whatever
  // the nesting. B is double, or four points in lanes (jet_lanes.hpp), each
  // lane the same operations as one point's but for sin, cos and ln.
  template <class B>
  MPMVV_JET_INLINE Vec2Of<B> body_force(const Vec2Of<B>& X, const SpaceFactorsOf<B>& space,
                                        const TimeFactorsOf<B>& time) const
    requires SeparableMotion<Motion>
  {
    std::array<TimeJetOf<B>, FactorCounts<Motion>::space> space_in_time;
    for (std::size_t k = 0; k < space.size(); ++k) space_in_time[k] = time_constant(base_value(space[k]));
    const TemporalOf<B> a = temporal_of(motion_.position(time_constants(X), space_in_time, time.in_time));
    const SpatialOf<B> s = spatial_of(motion_.position(space_variables(X), space, time.in_space), X);
    const Vec2Of<B> div = divergence(s, X);
    const B density(density_);
    return Vec2Of<B>(a.acceleration[0] - div[0] / density, a.acceleration[1] - div[1] / density);
  }

  // The fields without the acceleration and the body force (NaN there),
  // for a fraction of fields' work: one evaluation of the motion in a jet
  // of X, Y and t gives position, F and velocity, where fields evaluates it
  // twice with second derivatives (d2x/dt2; dF/dX for Div P); the stresses
  // come from F in value-only jets (Jet0), which divide as fields' jets do
  // (by a product with the inverse). Each partial derivative of a jet is
  // formed from the values and itself alone, and the value part of a nested
  // jet is the inner jet's own evaluation, so every value is fields' to the
  // bit (test_manufactured.cpp: StateIsFieldsWithoutTheBodyForce).
  ExactFields state(const Vec2& X, double t) const {
    using Jet3 = Jet<double, 3>;  // X, Y, t
    const Eigen::Matrix<Jet3, 2, 1> XJ(Jet3::variable(X.x(), 0), Jet3::variable(X.y(), 1));
    const Eigen::Matrix<Jet3, 2, 1> x = motion_.position(XJ, Jet3::variable(t, 2));
    ExactFields f;
    f.position = Vec2(x[0].v, x[1].v);
    f.displacement = f.position - X;
    f.velocity = Vec2(x[0].d[2], x[1].d[2]);
    f.acceleration = Vec2::Constant(std::numeric_limits<double>::quiet_NaN());
    Mat0 F;
    for (int i = 0; i < 2; ++i)
      for (int K = 0; K < 2; ++K) F(i, K) = Jet0(x[i].d[K]);
    const Jet0 F33 = geometry_ == Geometry::axisymmetric ? Jet0(x[0].v) / Jet0(X.x()) : Jet0(1.0);
    const Stress<Jet0> sigma = material_.stress(F, F33);
    Mat0 P;
    Jet0 P33;
    first_piola(F, F33, sigma, P, P33);
    f.deformation_gradient = value(F);
    f.hoop_stretch = F33.v;
    f.J = determinant(f.deformation_gradient) * f.hoop_stretch;
    f.cauchy_stress = value(sigma.in_plane);
    f.cauchy_stress_33 = sigma.out_of_plane.v;
    f.first_piola = value(P);
    f.first_piola_33 = P33.v;
    f.body_force = Vec2::Constant(std::numeric_limits<double>::quiet_NaN());
    return f;
  }

 private:
  using Vec2J = Eigen::Matrix<Jet2, 2, 1>;
  using Mat2J = Eigen::Matrix<Jet2, 2, 2>;
  using Jet0 = Jet<double, 0>;  // a value with no derivative, in the jets' arithmetic
  using Mat0 = Eigen::Matrix<Jet0, 2, 2>;

  template <class B>
  struct TemporalOf {
    Vec2Of<B> position, velocity, acceleration;
  };
  using Temporal = TemporalOf<double>;
  // F, F_33 and the stresses at X, each carrying its derivative along X.
  template <class B>
  struct SpatialOf {
    Eigen::Matrix<Jet<B, 2>, 2, 2> F;
    Jet<B, 2> F33;
    Stress<Jet<B, 2>> sigma;
    Eigen::Matrix<Jet<B, 2>, 2, 2> P;
    Jet<B, 2> P33;
  };
  using Spatial = SpatialOf<double>;

  template <class M>
  static Mat2 value(const M& m) {
    Mat2 r;
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) r(i, j) = m(i, j).v;
    return r;
  }

  // t seeded in the inner jet (for v) and in the outer jet (for a); X constant.
  static TimeJet time_variable(double t) { return TimeJet(Jet1::variable(t, 0), {Jet1(1.0)}); }
  template <class B>
  MPMVV_JET_INLINE static TimeJetOf<B> time_constant(const B& x) {
    return TimeJetOf<B>(Jet<B, 1>(x, {}), {});
  }
  template <class B>
  MPMVV_JET_INLINE static Eigen::Matrix<TimeJetOf<B>, 2, 1> time_constants(const Vec2Of<B>& X) {
    return Eigen::Matrix<TimeJetOf<B>, 2, 1>(time_constant(X.x()), time_constant(X.y()));
  }
  // X_J seeded in the inner jet (for F) and in the outer jet (for dF/dX).
  template <class B>
  MPMVV_JET_INLINE static Eigen::Matrix<SpaceJetOf<B>, 2, 1> space_variables(const Vec2Of<B>& X) {
    Eigen::Matrix<SpaceJetOf<B>, 2, 1> XJ;
    for (int J = 0; J < 2; ++J) {
      std::array<Jet<B, 2>, 2> outer{};
      outer[std::size_t(J)] = Jet<B, 2>(1.0);
      XJ[J] = SpaceJetOf<B>(Jet<B, 2>::variable(X[J], J), outer);
    }
    return XJ;
  }

  Temporal temporal(const Vec2& X, double t) const {
    return temporal_of(motion_.position(time_constants(X), time_variable(t)));
  }
  template <class B>
  MPMVV_JET_INLINE static TemporalOf<B> temporal_of(const Eigen::Matrix<TimeJetOf<B>, 2, 1>& x) {
    TemporalOf<B> r;
    for (int i = 0; i < 2; ++i) {
      r.position[i] = x[i].v.v;
      r.velocity[i] = x[i].v.d[0];
      r.acceleration[i] = x[i].d[0].d[0];
    }
    return r;
  }

  Spatial spatial(const Vec2& X, double t) const { return spatial_of(motion_.position(space_variables(X), SpaceJet(t)), X); }
  // F, F_33 and the stresses from the position x(X) in the jet of X.
  template <class B>
  MPMVV_JET_INLINE SpatialOf<B> spatial_of(const Eigen::Matrix<SpaceJetOf<B>, 2, 1>& x, const Vec2Of<B>& X) const {
    using J2 = Jet<B, 2>;
    SpatialOf<B> s;
    for (int i = 0; i < 2; ++i)
      for (int K = 0; K < 2; ++K) s.F(i, K) = J2(x[i].v.d[K], {x[i].d[0].d[K], x[i].d[1].d[K]});
    if (geometry_ == Geometry::axisymmetric) {
      const J2 r(x[0].v.v, {x[0].d[0].v, x[0].d[1].v});
      s.F33 = r / J2::variable(X.x(), 0);
    } else {
      s.F33 = J2(1.0);
    }
    s.sigma = material_.stress(s.F, s.F33);
    first_piola(s.F, s.F33, s.sigma, s.P, s.P33);
    return s;
  }

  // P = J sigma F^-T and P_33 = J sigma_33 / F_33, J = det F F_33, in the
  // arithmetic of either jet (spatial; state's value-only jets).
  template <class T>
  MPMVV_JET_INLINE static void first_piola(const Eigen::Matrix<T, 2, 2>& F, const T& F33, const Stress<T>& sigma,
                          Eigen::Matrix<T, 2, 2>& P, T& P33) {
    const T det2 = F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0);
    const T J = det2 * F33;
    Eigen::Matrix<T, 2, 2> F_inv_t;
    F_inv_t << F(1, 1) / det2, -F(1, 0) / det2, -F(0, 1) / det2, F(0, 0) / det2;
    P = J * sigma.in_plane * F_inv_t;
    P33 = J * sigma.out_of_plane / F33;
  }

  template <class B>
  MPMVV_JET_INLINE Vec2Of<B> divergence(const SpatialOf<B>& s, const Vec2Of<B>& X) const {
    Vec2Of<B> div(s.P(0, 0).d[0] + s.P(0, 1).d[1], s.P(1, 0).d[0] + s.P(1, 1).d[1]);
    if (geometry_ == Geometry::axisymmetric) {
      div.x() += (s.P(0, 0).v - s.P33.v) / X.x();
      div.y() += s.P(1, 0).v / X.x();
    }
    return div;
  }

  Motion motion_;
  Material material_;
  double density_;
  Geometry geometry_;
};

}  // namespace mpmvv::mms
