// The preconditioner of the implicit static step (static_stepper.hpp): the
// small-strain tangent K = sum_p V_p B_p^T C B_p in the unknowns, with C the
// small-strain elasticity of the material,
//   K_ab = V (lambda g_a g_b^T + mu g_b g_a^T + mu (g_a . g_b) I),
// factorized by Eigen's sparse LDL^T.
#pragma once

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

#include "solver/material/stress.hpp"
#include "solver/particles.hpp"
#include "solver/shape/stencil.hpp"
#include "unknowns.hpp"

namespace mpmvv {

class SmallStrainTangent {
 public:
  // Couplings a particle makes between nodes at most this many cells apart
  // enter the preconditioner (farther ones, from domains stretched past two
  // cells, are left out of it: it stays a preconditioner).
  static constexpr int kReach = 2;
  static constexpr int kSpan = 2 * kReach + 1;

  template <class Shape>
  void assemble(const Shape& shape, const Particles& P, const GridGeometry& grid, const SmallStrainModuli& moduli,
                const GridUnknowns& unknowns) {
    const auto start = std::chrono::steady_clock::now();
    const std::size_t nodes = grid.node_count();
    const int nx = grid.nodes_x();
    blocks_.assign(nodes * kSpan * kSpan, Mat2::Zero());
    Stencil<Shape::stencil_size> s;
    int node[Shape::stencil_size];
    Vec2 gradient[Shape::stencil_size];
    for (std::size_t p = 0; p < P.size(); ++p) {
      shape.evaluate(p, s);
      // Merge the stencil's repeated nodes (CPDI's corners share nodes),
      // leaving out entries that carry nothing.
      const int distinct = merged_gradients(
          s, node, gradient, [&](int k) { return s.weight[k] == 0.0 && s.gradient[k].isZero(); });
      const double V = P.volume[p];
      for (int a = 0; a < distinct; ++a)
        for (int b = 0; b < distinct; ++b) {
          const int di = node[b] % nx - node[a] % nx, dj = node[b] / nx - node[a] / nx;
          if (std::abs(di) > kReach || std::abs(dj) > kReach) continue;
          const Vec2& ga = gradient[a];
          const Vec2& gb = gradient[b];
          const Mat2 K = V * (moduli.lambda * ga * gb.transpose() + moduli.mu * gb * ga.transpose() +
                              moduli.mu * ga.dot(gb) * Mat2::Identity());
          blocks_[std::size_t(node[a]) * kSpan * kSpan + std::size_t((dj + kReach) * kSpan + di + kReach)] += K;
        }
    }
    factorize(grid, unknowns);
    factored_ = unknowns.numbering();
    seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  // Whether the factorization numbers the unknowns as `unknowns` does.
  bool serves(const GridUnknowns& unknowns) const { return factored_ == unknowns.numbering(); }
  Eigen::VectorXd solve(const Eigen::Ref<const Eigen::VectorXd>& v) const { return factor_.solve(v); }
  // Wall time spent assembling and factorizing so far.
  double seconds() const { return seconds_; }

 private:
  void factorize(const GridGeometry& grid, const GridUnknowns& unknowns) {
    const int nx = grid.nodes_x();
    std::vector<Eigen::Triplet<double>> triplets;
    double largest = 0.0;
    for (std::size_t a = 0; a < grid.node_count(); ++a) {
      const NodeMap& ma = unknowns.node(a);
      if (ma.dof[0] < 0 && ma.dof[1] < 0) continue;
      const int ia = int(a) % nx, ja = int(a) / nx;
      for (int dj = -kReach; dj <= kReach; ++dj)
        for (int di = -kReach; di <= kReach; ++di) {
          const Mat2& K = blocks_[a * kSpan * kSpan + std::size_t((dj + kReach) * kSpan + di + kReach)];
          if (K.isZero()) continue;
          const int ib = ia + di, jb = ja + dj;
          if (ib < 0 || jb < 0 || ib >= nx || jb >= grid.nodes_y()) continue;
          const NodeMap& mb = unknowns.node(std::size_t(grid.node(ib, jb)));
          for (int k = 0; k < 2; ++k)
            for (int l = 0; l < 2; ++l)
              if (ma.dof[k] >= 0 && mb.dof[l] >= 0) {
                const double value = ma.direction[k].dot(K * mb.direction[l]);
                triplets.emplace_back(ma.dof[k], mb.dof[l], value);
                if (ma.dof[k] == mb.dof[l]) largest = std::max(largest, std::abs(value));
              }
        }
    }
    // Nodes that particles barely reach have almost no stiffness: a small
    // diagonal keeps the factorization definite (it only preconditions).
    const int dofs = unknowns.count();
    for (int k = 0; k < dofs; ++k) triplets.emplace_back(k, k, 1e-10 * largest);
    Eigen::SparseMatrix<double> K(dofs, dofs);
    K.setFromTriplets(triplets.begin(), triplets.end());
    factor_.compute(K);
    if (factor_.info() != Eigen::Success) throw std::runtime_error("the preconditioner's LDL^T factorization failed");
  }

  std::vector<Mat2> blocks_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factor_;
  std::vector<int> factored_;  // the unknowns' numbering when factor_ was computed; empty before
  double seconds_ = 0.0;
};

}  // namespace mpmvv
