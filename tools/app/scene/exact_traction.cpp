#include "exact_traction.hpp"

#include <array>
#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include <fmt/format.h>

namespace mpmvv::app {

namespace {

// The force on each side by 3-point Gauss-Legendre quadrature of P N along
// its reference span: exact for a P quadratic along the side, and for the
// affine motions of the patch tests (P constant) to round-off.
class ExactRectangleTraction final : public BoundaryTraction {
 public:
  ExactRectangleTraction(std::vector<BoundaryEdge> edges, std::vector<Vec2> normals,
                         std::shared_ptr<const mms::ExactSolution> solution)
      : BoundaryTraction(std::move(edges)), normals_(std::move(normals)), solution_(std::move(solution)) {}

  void evaluate(double t, std::vector<Vec2>& force) const override {
    static const double r = std::sqrt(0.6);
    static const std::array<std::pair<double, double>, 3> gauss = {
        {{-r, 5.0 / 9.0}, {0.0, 8.0 / 9.0}, {r, 5.0 / 9.0}}};
    const std::vector<BoundaryEdge>& sides = edges();
    force.resize(sides.size());
    for (std::size_t e = 0; e < sides.size(); ++e) {
      const Vec2 &A = sides[e].A, &B = sides[e].B;
      const double half_length = 0.5 * (B - A).norm();
      Vec2 f = Vec2::Zero();
      for (const auto& [xi, w] : gauss) {
        const Vec2 X = 0.5 * (A + B) + 0.5 * xi * (B - A);
        f += (w * half_length) * (solution_->state(X, t).first_piola * normals_[e]);
      }
      force[e] = f;
    }
  }

 private:
  std::vector<Vec2> normals_;
  std::shared_ptr<const mms::ExactSolution> solution_;
};

}  // namespace

std::shared_ptr<BoundaryTraction> exact_rectangle_traction(std::shared_ptr<const mms::ExactSolution> solution,
                                                           const Vec2& lower, const Vec2& upper, const Particles& P,
                                                           const Vec2& half) {
  const double tolerance = 1e-9 * (upper - lower).maxCoeff();
  std::vector<BoundaryEdge> edges;
  std::vector<Vec2> normals;
  int sides_reached = 0;
  for (int side = 0; side < 4; ++side) {
    // bottom, right, top, left: the outward normal and which bound it is.
    const int axis = side % 2 == 0 ? 1 : 0;
    const bool high = side == 1 || side == 2;
    Vec2 N = Vec2::Zero();
    N[axis] = high ? 1.0 : -1.0;
    const double bound = high ? upper[axis] : lower[axis];
    const std::size_t before = edges.size();
    for (std::size_t p = 0; p < P.size(); ++p) {
      const Vec2 l = P.half_size.empty() ? half : P.half_size[p];
      const Vec2& X = P.reference_position[p];
      if (std::abs(X[axis] + (high ? l[axis] : -l[axis]) - bound) > tolerance) continue;
      const int along = 1 - axis;
      Vec2 A = X, B = X;
      A[axis] = B[axis] = bound;
      A[along] -= l[along];
      B[along] += l[along];
      edges.push_back({p, A, B});
      normals.push_back(N);
    }
    if (edges.size() > before) ++sides_reached;
  }
  if (sides_reached < 4)
    throw std::invalid_argument(fmt::format("the boundary traction found particle domains on {} of the rectangle's four "
                                            "sides: the seeding must fill the rectangle to its sides",
                                            sides_reached));
  return std::make_shared<ExactRectangleTraction>(std::move(edges), std::move(normals), std::move(solution));
}

}  // namespace mpmvv::app
