#include "snapshots.hpp"

#include <algorithm>
#include <string>

#include "solver/tensor.hpp"

namespace mpmvv::app {

void ParticleSnapshots::record(double t, const Particles& P, const mms::ExactSolution* exact,
                               const std::vector<Vec2>& tracers) {
  const std::size_t n = P.size();
  std::vector<double> X(2 * n), x(2 * n), u(2 * n), v(2 * n), J(n), s(4 * n), F(4 * n), e, tracer(2 * tracers.size());
  for (std::size_t i = 0; i < tracers.size(); ++i) {
    tracer[2 * i] = tracers[i].x();
    tracer[2 * i + 1] = tracers[i].y();
  }
  for (std::size_t p = 0; p < n; ++p) {
    for (int a = 0; a < 2; ++a) {
      X[2 * p + a] = P.reference_position[p][a];
      x[2 * p + a] = P.position[p][a];
      u[2 * p + a] = P.position[p][a] - P.reference_position[p][a];
      v[2 * p + a] = P.velocity[p][a];
    }
    J[p] = determinant(P.deformation_gradient[p]);
    for (int k = 0; k < 4; ++k) {
      s[4 * p + k] = P.stress[p](k / 2, k % 2);
      F[4 * p + k] = P.deformation_gradient[p](k / 2, k % 2);
    }
  }
  if (exact) {
    e.resize(2 * n);
#pragma omp parallel for schedule(static)
    for (std::size_t p = 0; p < n; ++p) {
      const Vec2 error = P.position[p] - exact->position(P.reference_position[p], t);
      e[2 * p] = error.x();
      e[2 * p + 1] = error.y();
    }
  }
  time_.push_back(t);
  reference_position_.push_back(std::move(X));
  reference_volume_.push_back(P.reference_volume);
  tracer_position_.push_back(std::move(tracer));
  position_.push_back(std::move(x));
  displacement_.push_back(std::move(u));
  velocity_.push_back(std::move(v));
  J_.push_back(std::move(J));
  stress_.push_back(std::move(s));
  F_.push_back(std::move(F));
  error_.push_back(std::move(e));
}

std::size_t ParticleSnapshots::largest_count() const {
  std::size_t n = 0;
  for (const std::vector<double>& J : J_) n = std::max(n, J.size());
  return n;
}

void ParticleSnapshots::write(h5::Group& root) const {
  if (time_.empty()) return;
  h5::Group all = root.create_group("snapshots");
  all.set_attribute("description",
                    "the particles at each output time k (group k): reference_position X [m], reference_volume "
                    "V0 [m^2 a unit depth, or m^3 a radian in r-z], position, displacement x - X [m], velocity "
                    "[m/s], J, Cauchy stress (in-plane, N x 2 x 2) [Pa], deformation_gradient (N x 2 x 2), "
                    "with an exact motion displacement_error x - x_exact(X, t) [m], and tracer_position (M x 2) "
                    "[m], the probes' material points in the order of /probes");
  for (std::size_t k = 0; k < time_.size(); ++k) {
    h5::Group g = all.create_group(std::to_string(k));
    const hsize_t n = J_[k].size();
    g.set_attribute("time", time_[k]);
    g.write("reference_position", reference_position_[k], {n, 2});
    g.write("reference_volume", reference_volume_[k], {n});
    g.write("position", position_[k], {n, 2});
    g.write("displacement", displacement_[k], {n, 2});
    g.write("velocity", velocity_[k], {n, 2});
    g.write("J", J_[k], {n});
    g.write("stress", stress_[k], {n, 2, 2});
    g.write("deformation_gradient", F_[k], {n, 2, 2});
    if (!error_[k].empty()) g.write("displacement_error", error_[k], {n, 2});
    g.write("tracer_position", tracer_position_[k], {tracer_position_[k].size() / 2, 2});
  }
}

void ParticleSnapshots::persist(StateArchive& a) {
  a.field("snapshot_time", time_);
  a.field("snapshot_reference_position", reference_position_);
  a.field("snapshot_reference_volume", reference_volume_);
  a.field("snapshot_tracer_position", tracer_position_);
  a.field("snapshot_position", position_);
  a.field("snapshot_displacement", displacement_);
  a.field("snapshot_velocity", velocity_);
  a.field("snapshot_J", J_);
  a.field("snapshot_stress", stress_);
  a.field("snapshot_F", F_);
  a.field("snapshot_error", error_);
}

}  // namespace mpmvv::app
