// Material points as structure-of-arrays. Fields a method or a scene does not
// use stay empty: a linear-MPM run has no particle domains, a scene without
// body force has no body-force array.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "tensor.hpp"

namespace mpmvv {

// The bytes a vector holds (its capacity).
template <class T>
std::size_t bytes_held(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}

struct Particles {
  // Advanced by every step.
  std::vector<Vec2> position;              // x_p
  std::vector<Vec2> velocity;              // v_p
  std::vector<Mat2> deformation_gradient;  // F_p, in-plane part (F_zz = 1, plane strain)
  std::vector<double> volume;              // V_p = det(F_p) V_p0, eq. 1.75
  std::vector<Mat2> stress;                // Cauchy sigma_p, in-plane part

  // Set once.
  std::vector<double> mass;                // m_p = rho_0 V_p0
  std::vector<double> reference_volume;    // V_p0
  std::vector<Vec2> reference_position;    // X_p

  // Method-specific: the half-size l_p of the reference particle domain along
  // x and y. GIMP uses it as is (uGIMP: the size is not convected); CPDI spans
  // its parallelogram with r_i = F_p (l_i e_i), eq. 1.97. Empty for linear MPM.
  std::vector<Vec2> half_size;

  // Optional, CPDI with turned domains only (domain_angle.hpp): the domain's
  // half-vectors in the reference configuration as the columns of A_p, the
  // current ones being F_p A_p. Empty otherwise, when A_p = diag(half_size).
  std::vector<Mat2> domain_axes;

  // Optional, CPDI with corner domains only (domain_corners.hpp): each
  // particle's four domain corners, 4 p + c counter-clockwise from
  // (xi, eta) = (-1, -1), moved with the grid velocity like material points.
  // Empty otherwise.
  std::vector<Vec2> domain_corner;

  // Optional, exact CPDI only: a particle domain of any polygonal shape, the
  // reference outline's points relative to X_p (domain_vertex[domain_first[p]]
  // up to domain_first[p + 1]); its current outline is x_p + F_p (X_k - X_p).
  // A particle with no points keeps the parallelogram of half_size. Seeding
  // gives the pieces a curved boundary cuts their own outline, so that the
  // domains tile the body exactly. Empty (both) when no particle has one.
  std::vector<std::uint32_t> domain_first;
  std::vector<Vec2> domain_vertex;

  // Axisymmetric runs only: the hoop stretch F_theta (r / R for the exact
  // motion) and the hoop stress sigma_theta.
  std::vector<double> hoop_stretch;
  std::vector<double> hoop_stress;

  // velocity_transfer = apic only: the particle's affine velocity field
  // C_p, its velocity at x being v_p + C_p (x - x_p) (model.hpp).
  std::vector<Mat2> affine_velocity;

  // Scene-specific: body force per unit mass b_p (eq. 1.71 uses m_p b_p).
  std::vector<Vec2> body_force;

  std::size_t size() const { return position.size(); }

  // Calls f(name, array) for every array above: what the bytes count and a
  // restart file stores (io/state_archive.hpp) are the same list.
  template <class Self, class F>
  static void for_each_array(Self& P, F&& f) {
    f("position", P.position);
    f("velocity", P.velocity);
    f("deformation_gradient", P.deformation_gradient);
    f("volume", P.volume);
    f("stress", P.stress);
    f("mass", P.mass);
    f("reference_volume", P.reference_volume);
    f("reference_position", P.reference_position);
    f("half_size", P.half_size);
    f("domain_axes", P.domain_axes);
    f("domain_corner", P.domain_corner);
    f("domain_first", P.domain_first);
    f("domain_vertex", P.domain_vertex);
    f("hoop_stretch", P.hoop_stretch);
    f("hoop_stress", P.hoop_stress);
    f("affine_velocity", P.affine_velocity);
    f("body_force", P.body_force);
  }

  // The bytes the arrays hold (their capacity).
  std::size_t bytes() const {
    std::size_t total = 0;
    for_each_array(*this, [&](const char*, const auto& v) { total += bytes_held(v); });
    return total;
  }

  // Every array, for a restart file (Archive: io/state_archive.hpp).
  template <class Archive>
  void persist(Archive& a) {
    for_each_array(*this, [&](const char* name, auto& v) { a.field(name, v); });
  }

  // A_p: the columns span particle p's reference domain about X_p.
  Mat2 reference_domain(std::size_t p) const {
    if (!domain_axes.empty()) return domain_axes[p];
    Mat2 a = Mat2::Zero();
    a(0, 0) = half_size[p].x();
    a(1, 1) = half_size[p].y();
    return a;
  }

  void resize(std::size_t n) {
    position.resize(n, Vec2::Zero());
    velocity.resize(n, Vec2::Zero());
    deformation_gradient.resize(n, Mat2::Identity());
    volume.resize(n, 0.0);
    stress.resize(n, Mat2::Zero());
    mass.resize(n, 0.0);
    reference_volume.resize(n, 0.0);
    reference_position.resize(n, Vec2::Zero());
  }
};

}  // namespace mpmvv
