// Rest at points of a boundary the grid's nodes do not lie on. A scene names
// points x_b where the exact motion is rest (the rims of the stiff vortex);
// the grid field v(x) = sum_g N_g(x) v_g, read with the method's grid basis
// (the hats, or the B-splines), is held at v(x_b) = 0 after every kick by the
// correction nearest in kinetic energy:
//   minimise sum_g m_g |v_g - v*_g|^2  subject to  C v = 0,  C_bg = N_g(x_b),
//   v = v* - M^-1 C^T lambda,   (C M^-1 C^T) lambda = C v*,
// with M the lumped node masses: the constraint forces -C^T lambda / dt act
// only along the constraint's rows (Lagrange multipliers), they do no work on
// the velocity they leave (C v = 0), and each component is held alike.
//
// Why not hold the nodes outside the boundary: for a basis that does not
// interpolate (a B-spline) a node's value is not the field's value there, and
// which nodes fall outside a curved boundary changes irregularly from mesh to
// mesh: the held set is a staircase a cell deep, and the field is held at
// rest a fraction of a cell inside the body. The L2 best fit of the stiff
// vortex's motion over t = 0-1 s (time-integrated, relative) with the nodes
// outside its rims held at zero is 0.030 (hats), 0.026 (quadratic) and 0.020
// (cubic B-splines) on 30 cells; with the rims themselves held, at points a
// cell apart, 0.026, 0.013 and 0.0031; with none held, 0.018, 0.0088 and
// 0.0021. The runs follow (suites/stiff-vortex.toml): cubic splines 0.069
// with the nodes held, 0.047 with the rims.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <utility>
#include <vector>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <fmt/format.h>

#include "grid.hpp"
#include "particles.hpp"
#include "shape/stencil.hpp"

namespace mpmvv {

// The grid basis of `Basis` (a point shape: linear, B-spline) at each point,
// as the rows of C. A point whose basis leaves the grid is refused by name.
template <class Basis>
std::vector<std::vector<std::pair<int, double>>> basis_rows(const GridGeometry& grid, const std::vector<Vec2>& points) {
  Particles at;
  at.position = points;
  const Basis basis = Basis::bind(grid, at);
  std::vector<std::vector<std::pair<int, double>>> rows(points.size());
  Stencil<Basis::stencil_size> st;
  for (std::size_t b = 0; b < points.size(); ++b) {
    if (!basis.inside(b))
      throw std::invalid_argument(fmt::format("the rest point ({:.6g}, {:.6g}) lies where the grid basis leaves "
                                              "the grid (outside the walls or too near one)",
                                              points[b].x(), points[b].y()));
    basis.evaluate(b, st);
    for (int k = 0; k < st.count; ++k)
      if (st.weight[k] != 0.0) rows[b].push_back({st.node[k], st.weight[k]});
  }
  return rows;
}

class RestPoints {
 public:
  // `prescribed`: two flags per grid node (boundary.hpp:
  // prescribed_components); a node a constraint moves along either axis keeps
  // its motion, as if of infinite mass.
  RestPoints(std::vector<std::vector<std::pair<int, double>>> rows, const std::vector<unsigned char>& prescribed)
      : rows_(std::move(rows)) {
    for (const auto& row : rows_)
      for (const auto& [node, w] : row) involved_.push_back(node);
    std::sort(involved_.begin(), involved_.end());
    involved_.erase(std::unique(involved_.begin(), involved_.end()), involved_.end());
    for (auto& row : rows_)
      for (auto& [node, w] : row)
        node = int(std::lower_bound(involved_.begin(), involved_.end(), node) - involved_.begin());
    for (int node : involved_) {
      const std::size_t i = 2 * std::size_t(node);
      prescribed_.push_back(i + 1 < prescribed.size() && (prescribed[i] || prescribed[i + 1]));
    }
  }

  std::size_t points() const { return rows_.size(); }

  // Holds v(x_b) = 0 on the kicked grid velocity and changes the acceleration
  // with it (a = (v - v_before) / kick).
  void apply(GridFields& g, double kick) {
    const std::size_t n = involved_.size();
    // A state already lost (a mass or velocity not finite) is left to the
    // health scan, which names the particle; the system is not formed on it.
    for (int node : involved_)
      if (!std::isfinite(g.mass[std::size_t(node)]) || !g.velocity[std::size_t(node)].allFinite()) return;
    bool same = mass_.size() == n;
    for (std::size_t k = 0; k < n && same; ++k) same = mass_[k] == g.mass[std::size_t(involved_[k])];
    if (!same) factor(g);
    if (active_.empty()) return;
    Eigen::VectorXd v(n);
    for (int axis = 0; axis < 2; ++axis) {
      for (std::size_t k = 0; k < n; ++k) v[Eigen::Index(k)] = g.velocity[std::size_t(involved_[k])][axis];
      const Eigen::VectorXd lambda = solver_.solve(C_ * v);
      if (!lambda.allFinite())
        throw std::runtime_error("rest points: the constraint system has no finite solution (points too close "
                                 "for the grid basis to hold them apart)");
      const Eigen::VectorXd dv = inv_mass_.cwiseProduct(C_.transpose() * lambda);
      for (std::size_t k = 0; k < n; ++k) {
        const std::size_t node = std::size_t(involved_[k]);
        g.velocity[node][axis] -= dv[Eigen::Index(k)];
        g.acceleration[node][axis] -= dv[Eigen::Index(k)] / kick;
      }
    }
  }

 private:
  // C over the rows that weigh a node with mass (a point no particle reaches
  // holds nothing), and S = C M^-1 C^T factored; again whenever a mass changes.
  void factor(const GridFields& g) {
    const std::size_t n = involved_.size();
    mass_.resize(n);
    inv_mass_.resize(Eigen::Index(n));
    for (std::size_t k = 0; k < n; ++k) {
      mass_[k] = g.mass[std::size_t(involved_[k])];
      inv_mass_[Eigen::Index(k)] = mass_[k] > 0.0 && !prescribed_[k] ? 1.0 / mass_[k] : 0.0;
    }
    active_.clear();
    std::vector<Eigen::Triplet<double>> entries;
    for (std::size_t b = 0; b < rows_.size(); ++b) {
      bool reaches = false;
      for (const auto& [k, w] : rows_[b]) reaches = reaches || inv_mass_[k] > 0.0;
      if (!reaches) continue;
      const int row = int(active_.size());
      active_.push_back(b);
      for (const auto& [k, w] : rows_[b])
        if (mass_[std::size_t(k)] > 0.0) entries.emplace_back(row, k, w);
    }
    C_.resize(Eigen::Index(active_.size()), Eigen::Index(n));
    C_.setFromTriplets(entries.begin(), entries.end());
    if (active_.empty()) return;
    Eigen::SparseMatrix<double> S = C_ * inv_mass_.asDiagonal() * C_.transpose();
    solver_.compute(S);
    // Rows can be redundant: two points whose only node with mass is the same
    // node ask for the same thing, and S is singular but C v* lies in its
    // range (range S = range C). The correction is then still unique, and
    // (S + delta I) lambda = C v* gives it with C v = delta lambda, a residual
    // of order delta / diag S = 1e-12 at the points.
    const double largest = S.diagonal().cwiseAbs().maxCoeff();
    const double pivot_floor = 1e-13 * largest;
    if (solver_.info() != Eigen::Success || !(solver_.vectorD().minCoeff() > pivot_floor)) {
      Eigen::SparseMatrix<double> shift(S.rows(), S.cols());
      shift.setIdentity();
      S += (1e-12 * largest) * shift;
      solver_.compute(S);
      if (solver_.info() != Eigen::Success)
        throw std::runtime_error("rest points: the constraint system could not be factored");
    }
  }

  std::vector<std::vector<std::pair<int, double>>> rows_;  // per point: (index into involved_, N_g(x_b))
  std::vector<int> involved_;                              // the grid nodes any point weighs, sorted
  std::vector<double> mass_;                               // their masses at the last factorization
  std::vector<unsigned char> prescribed_;                  // per involved node: a node constraint sets it
  Eigen::VectorXd inv_mass_;
  std::vector<std::size_t> active_;                        // points that weigh a node with mass
  Eigen::SparseMatrix<double> C_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver_;
};

}  // namespace mpmvv
