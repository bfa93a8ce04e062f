// The derived body force of a separable motion (manufactured.hpp) as a force
// field: each point keeps the motion's factors of X with their gradients and
// Hessians along X (9 doubles a factor), which do not change along the
// particle's path, and an evaluation forms the factors of t once for all
// points. What is left per point and step is the combination of the factors
// in the jets, the material in the jet of X and the divergence: the same jets
// as Manufactured::body_force(X, t), so the same force to the bit
// (tests/test_manufactured.cpp), for a fraction of the work
// (mpmvv-bench-forcing).
//
// Four points at a time in lanes (jet_lanes.hpp): every jet operation is the
// same on four points, so where the CPU has AVX2 (solver/lanes.hpp:
// lane_build) one vector instruction does it for all four. The function that
// runs a block of points is compiled once for AVX2 (the target attribute) and
// once for any x86-64, with everything it calls inlined into it (flatten): a
// vector operation is lowered for the instructions of the function it ends
// up in, and the motion, the material and Eigen's products are inlined into
// each copy, so no function the baseline build may call carries AVX2. The
// choice is made once an evaluation, not per point.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include "force_field.hpp"
#include "jet_lanes.hpp"
#include "manufactured.hpp"
#include "solver/lanes.hpp"

namespace mpmvv::mms {

template <SeparableMotion Motion, class Material>
class FactoredForceField final : public ForceField {
  using Solution = Manufactured<Motion, Material>;
  using LaneTime = typename Solution::template TimeFactorsOf<JetLanes>;
  static constexpr std::size_t kLaneCount = JetLanes::kCount;
  // Points a thread takes at a time: a multiple of the lanes.
  static constexpr std::size_t kBlock = 64;

 public:
  // `build`: the vector build the blocks run (lane_build by default; one the
  // CPU has, for tests that compare the builds).
  explicit FactoredForceField(Solution manufactured, LaneBuild build = lane_build())
      : m_(std::move(manufactured)), build_(build) {}

  void place(std::size_t count, const std::vector<std::size_t>& index, const std::vector<Vec2>& at) override {
    place_points(points_, count, index, at);
    factors_.resize(count);
    const std::size_t n = index.size();
#pragma omp parallel for schedule(static)
    for (std::size_t k = 0; k < n; ++k) factors_[index[k]] = m_.space_factors(at[k]);
  }

  void evaluate(double t, std::vector<Vec2>& b) const override {
    const typename Solution::TimeFactors time = m_.time_factors(t);
    LaneTime lanes;
    for (std::size_t k = 0; k < time.in_time.size(); ++k) {
      lanes.in_time[k] = to_lanes(time.in_time[k]);
      lanes.in_space[k] = to_lanes(time.in_space[k]);
    }
    const std::size_t n = points_.size();
    const std::size_t blocks = (n + kBlock - 1) / kBlock;
#if defined(__x86_64__)
    const bool vector = build_ != LaneBuild::baseline;
#else
    const bool vector = false;
#endif
#pragma omp parallel for schedule(static)
    for (std::size_t k = 0; k < blocks; ++k) {
      const std::size_t first = k * kBlock, last = std::min(n, first + kBlock);
      if (vector) block_vector(*this, first, last, lanes, b.data());
      else block_baseline(*this, first, last, lanes, b.data());
    }
  }

  std::size_t bytes() const override { return bytes_held(points_) + bytes_held(factors_); }

 private:
#if defined(__x86_64__)
  __attribute__((target("avx2"), flatten)) static void block_vector(const FactoredForceField& f, std::size_t first,
                                                                    std::size_t last, const LaneTime& time, Vec2* b) {
    f.block(first, last, time, b);
  }
#else
  static void block_vector(const FactoredForceField& f, std::size_t first, std::size_t last, const LaneTime& time,
                           Vec2* b) {
    block_baseline(f, first, last, time, b);
  }
#endif
  __attribute__((flatten)) static void block_baseline(const FactoredForceField& f, std::size_t first,
                                                      std::size_t last, const LaneTime& time, Vec2* b) {
    f.block(first, last, time, b);
  }

  // Points first, ..., last - 1, four at a time; a last group of fewer
  // repeats its first point in the spare lanes (their forces are dropped).
  MPMVV_JET_INLINE void block(std::size_t first, std::size_t last, const LaneTime& time, Vec2* b) const {
    constexpr std::size_t K = FactorCounts<Motion>::space;
    for (std::size_t p0 = first; p0 < last; p0 += kLaneCount) {
      const std::size_t count = std::min(kLaneCount, last - p0);
      // Each lane's point and factors (a factor's 9 parts in the order of its
      // jets: value, inner gradient, then each outer partial with its own).
      alignas(32) double x[kLaneCount], y[kLaneCount], parts[K][9][kLaneCount];
      for (std::size_t l = 0; l < kLaneCount; ++l) {
        const std::size_t p = p0 + (l < count ? l : 0);
        x[l] = points_[p].x();
        y[l] = points_[p].y();
        for (std::size_t k = 0; k < K; ++k) {
          const auto& f = factors_[p][k];
          const double part[9] = {f.v.v,    f.v.d[0],    f.v.d[1],    f.d[0].v,   f.d[0].d[0],
                                  f.d[0].d[1], f.d[1].v, f.d[1].d[0], f.d[1].d[1]};
          for (int j = 0; j < 9; ++j) parts[k][j][l] = part[j];
        }
      }
      const Eigen::Matrix<JetLanes, 2, 1> X(JetLanes::load(x), JetLanes::load(y));
      typename Solution::template SpaceFactorsOf<JetLanes> space;
      for (std::size_t k = 0; k < K; ++k) {
        auto& s = space[k];
        s.v = {JetLanes::load(parts[k][0]), {JetLanes::load(parts[k][1]), JetLanes::load(parts[k][2])}};
        for (int i = 0; i < 2; ++i)
          s.d[i] = {JetLanes::load(parts[k][3 + 3 * i]),
                    {JetLanes::load(parts[k][4 + 3 * i]), JetLanes::load(parts[k][5 + 3 * i])}};
      }
      const Eigen::Matrix<JetLanes, 2, 1> force = m_.body_force(X, space, time);
      for (std::size_t l = 0; l < count; ++l) b[p0 + l] = Vec2(force[0][int(l)], force[1][int(l)]);
    }
  }

  Solution m_;
  LaneBuild build_;
  std::vector<Vec2> points_;
  std::vector<typename Solution::SpaceFactors> factors_;
};

}  // namespace mpmvv::mms
