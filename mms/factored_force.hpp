// The derived body force of a separable motion (manufactured.hpp) as a force
// field: each point keeps the motion's factors of X with their gradients and
// Hessians along X (9 doubles a factor), which do not change along the
// particle's path, and an evaluation forms the factors of t once for all
// points. What is left per point and step is the combination of the factors
// in the jets, the material in the jet of X and the divergence: the same jets
// as Manufactured::body_force(X, t), for a fraction of the work
// (mpmvv-bench-forcing). The same force but for the last places of sin, cos
// and ln, which the lanes take from the solver's lane functions
// (jet_lanes.hpp; tests/test_manufactured.cpp bounds the difference).
//
// Points in lanes (jet_lanes.hpp): every jet operation is the same on every
// point, so one vector instruction does it for four (AVX2) or eight
// (AVX-512) at once, where the CPU has them (solver/lanes.hpp: lane_build).
// The function that runs a block of points is compiled for AVX-512 with
// eight lanes, for AVX2 and for any x86-64 with four (the target
// attribute), with everything it calls inlined into it (flatten): a vector
// operation is lowered for the instructions of the function it ends up in,
// and the motion, the material and Eigen's products are inlined into each
// copy, so no function the baseline build may call carries AVX2. No build
// fuses a multiply with an add (AVX2 as targeted here has no FMA; the
// AVX-512 copy is compiled with fp-contract off, without which its forces
// differed in their last places), so every build gives the same bits
// (tests/test_manufactured.cpp).
// The choice is made once an evaluation, not per point.
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
  template <int W>
  using LaneTime = typename Solution::template TimeFactorsOf<JetLanesOf<W>>;
  // Points a group holds: the widest build's lanes.
  static constexpr std::size_t kGroup = 8;
  // Points a thread takes at a time: a multiple of a group.
  static constexpr std::size_t kBlock = 64;

 public:
  // `build`: the vector build the blocks run (lane_build by default; one the
  // CPU has, for tests that compare the builds).
  explicit FactoredForceField(Solution manufactured, LaneBuild build = lane_build())
      : m_(std::move(manufactured)), build_(build) {}

  void place(std::size_t count, const std::vector<std::size_t>& index, const std::vector<Vec2>& at) override {
    count_ = count;
    groups_.resize((count + kGroup - 1) / kGroup);
    const std::size_t n = index.size();
#pragma omp parallel for schedule(static)
    for (std::size_t k = 0; k < n; ++k) put(index[k], at[k]);
    // The last group's spare lanes repeat its first point (their forces are
    // dropped): a lane of no point would compute on whatever it held.
    if (const std::size_t used = count % kGroup; used != 0) {
      LaneGroup& g = groups_.back();
      for (std::size_t l = used; l < kGroup; ++l) copy_lane(g, 0, l);
    }
  }

  void evaluate(double t, std::vector<Vec2>& b) const override {
    const typename Solution::TimeFactors time = m_.time_factors(t);
    LaneTime<4> four;
    LaneTime<8> eight;
    for (std::size_t k = 0; k < time.in_time.size(); ++k) {
      four.in_time[k] = to_lanes<4>(time.in_time[k]);
      four.in_space[k] = to_lanes<4>(time.in_space[k]);
      eight.in_time[k] = to_lanes<8>(time.in_time[k]);
      eight.in_space[k] = to_lanes<8>(time.in_space[k]);
    }
    const std::size_t n = count_;
    const std::size_t blocks = (n + kBlock - 1) / kBlock;
    [[maybe_unused]] const LaneBuild build = build_;  // read only on x86-64
#pragma omp parallel for schedule(static)
    for (std::size_t k = 0; k < blocks; ++k) {
      const std::size_t first = k * kBlock, last = std::min(n, first + kBlock);
#if defined(__x86_64__)
      if (build == LaneBuild::avx512) {
        block_avx512(*this, first, last, eight, b.data());
        continue;
      }
      if (build == LaneBuild::avx2) {
        block_avx2(*this, first, last, four, b.data());
        continue;
      }
#endif
      block_baseline(*this, first, last, four, b.data());
    }
  }

  std::size_t bytes() const override { return bytes_held(groups_); }

 private:
#if defined(__x86_64__)
  __attribute__((target("avx512f,avx512dq,avx512vl"), optimize("fp-contract=off"), flatten)) static void block_avx512(
      const FactoredForceField& f, std::size_t first, std::size_t last, const LaneTime<8>& time, Vec2* b) {
    f.block<8>(first, last, time, b);
  }
  __attribute__((target("avx2"), flatten)) static void block_avx2(const FactoredForceField& f, std::size_t first,
                                                                  std::size_t last, const LaneTime<4>& time, Vec2* b) {
    f.block<4>(first, last, time, b);
  }
#endif
  __attribute__((flatten)) static void block_baseline(const FactoredForceField& f, std::size_t first,
                                                      std::size_t last, const LaneTime<4>& time, Vec2* b) {
    f.block<4>(first, last, time, b);
  }

  static constexpr std::size_t K = FactorCounts<Motion>::space;
  // Eight points in lanes: point p is lane p % 8 of group p / 8, its place
  // and its factors of X, each factor's 9 parts in the order of its jets
  // (value, inner gradient, then each outer partial with its own), so that
  // an evaluation loads each part of eight (or four) points as one vector.
  struct LaneGroup {
    alignas(64) double x[kGroup], y[kGroup], parts[K][9][kGroup];
  };

  void put(std::size_t p, const Vec2& X) {
    LaneGroup& g = groups_[p / kGroup];
    const std::size_t l = p % kGroup;
    g.x[l] = X.x();
    g.y[l] = X.y();
    const typename Solution::SpaceFactors factors = m_.space_factors(X);
    for (std::size_t k = 0; k < K; ++k) {
      const auto& f = factors[k];
      const double part[9] = {f.v.v,    f.v.d[0],    f.v.d[1],    f.d[0].v,   f.d[0].d[0],
                              f.d[0].d[1], f.d[1].v, f.d[1].d[0], f.d[1].d[1]};
      for (int j = 0; j < 9; ++j) g.parts[k][j][l] = part[j];
    }
  }
  static void copy_lane(LaneGroup& g, std::size_t from, std::size_t to) {
    g.x[to] = g.x[from];
    g.y[to] = g.y[from];
    for (std::size_t k = 0; k < K; ++k)
      for (int j = 0; j < 9; ++j) g.parts[k][j][to] = g.parts[k][j][from];
  }

  // Points first, ..., last - 1 (first a multiple of a group), W at a time
  // (a group or half of one); a last W of fewer computes its spare lanes too
  // and drops them.
  template <int W>
  MPMVV_JET_INLINE void block(std::size_t first, std::size_t last, const LaneTime<W>& time, Vec2* b) const {
    using Lanes = JetLanesOf<W>;
    for (std::size_t p0 = first; p0 < last; p0 += W) {
      const std::size_t count = std::min(std::size_t(W), last - p0);
      const LaneGroup& g = groups_[p0 / kGroup];
      const std::size_t l0 = p0 % kGroup;
      const Eigen::Matrix<Lanes, 2, 1> X(Lanes::load(g.x + l0), Lanes::load(g.y + l0));
      typename Solution::template SpaceFactorsOf<Lanes> space;
      for (std::size_t k = 0; k < K; ++k) {
        auto& s = space[k];
        const auto& parts = g.parts[k];
        s.v = {Lanes::load(parts[0] + l0), {Lanes::load(parts[1] + l0), Lanes::load(parts[2] + l0)}};
        for (int i = 0; i < 2; ++i)
          s.d[i] = {Lanes::load(parts[3 + 3 * i] + l0),
                    {Lanes::load(parts[4 + 3 * i] + l0), Lanes::load(parts[5 + 3 * i] + l0)}};
      }
      const Eigen::Matrix<Lanes, 2, 1> force = m_.body_force(X, space, time);
      for (std::size_t l = 0; l < count; ++l) b[p0 + l] = Vec2(force[0][int(l)], force[1][int(l)]);
    }
  }

  Solution m_;
  LaneBuild build_;
  std::size_t count_ = 0;  // points
  std::vector<LaneGroup> groups_;
};

}  // namespace mpmvv::mms
