// The derived body force of a separable motion (manufactured.hpp) as a force
// field: each point keeps the motion's factors of X with their gradients and
// Hessians along X (9 doubles a factor), which do not change along the
// particle's path, and an evaluation forms the factors of t once for all
// points. What is left per point and step is the combination of the factors
// in the jets, the material in the jet of X and the divergence: the same jets
// as Manufactured::body_force(X, t), so the same force to the bit
// (tests/test_manufactured.cpp), for a fraction of the work
// (mpmvv-bench-forcing).
#pragma once

#include <cstddef>
#include <vector>

#include "force_field.hpp"
#include "manufactured.hpp"

namespace mpmvv::mms {

template <SeparableMotion Motion, class Material>
class FactoredForceField final : public ForceField {
 public:
  explicit FactoredForceField(Manufactured<Motion, Material> manufactured) : m_(std::move(manufactured)) {}

  void place(std::size_t count, const std::vector<std::size_t>& index, const std::vector<Vec2>& at) override {
    place_points(points_, count, index, at);
    factors_.resize(count);
    const std::size_t n = index.size();
#pragma omp parallel for schedule(static)
    for (std::size_t k = 0; k < n; ++k) factors_[index[k]] = m_.space_factors(at[k]);
  }

  void evaluate(double t, std::vector<Vec2>& b) const override {
    const typename Manufactured<Motion, Material>::TimeFactors time = m_.time_factors(t);
    const std::size_t n = points_.size();
#pragma omp parallel for schedule(static)
    for (std::size_t p = 0; p < n; ++p) b[p] = m_.body_force(points_[p], factors_[p], time);
  }

  std::size_t bytes() const override { return bytes_held(points_) + bytes_held(factors_); }

 private:
  Manufactured<Motion, Material> m_;
  std::vector<Vec2> points_;
  std::vector<typename Manufactured<Motion, Material>::SpaceFactors> factors_;
};

}  // namespace mpmvv::mms
