// A manufactured solution behind one interface, so that scenes and the
// command line choose motion and material at run time. Calls are per point
// (for probes, checks and people) or per particle array (the body-force stage:
// one virtual call per step, the loop inside).
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "factored_force.hpp"
#include "force_field.hpp"
#include "manufactured.hpp"
#include "residual_check.hpp"
#include "solver/model.hpp"

namespace mpmvv::mms {

class ExactSolution {
 public:
  virtual ~ExactSolution() = default;
  virtual Geometry geometry() const = 0;
  virtual double density() const = 0;
  virtual Vec2 position(const Vec2& X, double t) const = 0;
  virtual ExactFields fields(const Vec2& X, double t) const = 0;
  // The same without the acceleration and the body force (NaN there), and
  // where a solution can, for less work (Manufactured::state): what the
  // seeding, and the errors and monitors at output times, read.
  virtual ExactFields state(const Vec2& X, double t) const {
    ExactFields f = fields(X, t);
    f.acceleration = f.body_force = Vec2::Constant(std::numeric_limits<double>::quiet_NaN());
    return f;
  }
  virtual Vec2 body_force(const Vec2& X, double t) const = 0;
  // b at every reference position (threads over the array).
  virtual void body_forces(double t, const std::vector<Vec2>& X, std::vector<Vec2>& b) const = 0;
  // The residual by finite differences with steps `step` times the motion's
  // length and time scales (Manufactured::check).
  virtual ResidualCheck check(const Vec2& X, double t, double step = kCheckStep) const = 0;
  // The derived force as a field that keeps what it can of each point
  // (factored_force.hpp), where the solution has one; derived_force_field
  // gives every solution's.
  // `build`: the vector build it runs (solver/lanes.hpp; tests compare them).
  virtual std::shared_ptr<ForceField> factored_force_field(LaneBuild build = lane_build()) const {
    (void)build;
    return nullptr;
  }
};

// The derived force as a field that evaluates the solution point by point.
class DerivedForceField final : public ForceField {
 public:
  explicit DerivedForceField(std::shared_ptr<const ExactSolution> solution) : solution_(std::move(solution)) {}
  void place(std::size_t count, const std::vector<std::size_t>& index, const std::vector<Vec2>& at) override {
    place_points(points_, count, index, at);
  }
  void evaluate(double t, std::vector<Vec2>& b) const override { solution_->body_forces(t, points_, b); }
  std::size_t bytes() const override { return bytes_held(points_); }

 private:
  std::shared_ptr<const ExactSolution> solution_;
  std::vector<Vec2> points_;
};

// The body force derived from `solution`'s motion and material (automatic
// differentiation, manufactured.hpp), as a field: factored where the motion
// is separable, point by point otherwise.
inline std::shared_ptr<ForceField> derived_force_field(std::shared_ptr<const ExactSolution> solution,
                                                       LaneBuild build = lane_build()) {
  if (std::shared_ptr<ForceField> factored = solution->factored_force_field(build)) return factored;
  return std::make_shared<DerivedForceField>(std::move(solution));
}

template <class Motion, class Material>
class ManufacturedSolution final : public ExactSolution {
 public:
  ManufacturedSolution(Motion motion, Material material, double density, Geometry geometry)
      : m_(std::move(motion), material, density, geometry) {}

  Geometry geometry() const override { return m_.geometry(); }
  double density() const override { return m_.density(); }
  Vec2 position(const Vec2& X, double t) const override { return m_.position(X, t); }
  ExactFields fields(const Vec2& X, double t) const override { return m_.fields(X, t); }
  ExactFields state(const Vec2& X, double t) const override { return m_.state(X, t); }
  Vec2 body_force(const Vec2& X, double t) const override { return m_.body_force(X, t); }
  void body_forces(double t, const std::vector<Vec2>& X, std::vector<Vec2>& b) const override {
    const std::size_t n = X.size();
#pragma omp parallel for schedule(static)
    for (std::size_t p = 0; p < n; ++p) b[p] = m_.body_force(X[p], t);
  }
  ResidualCheck check(const Vec2& X, double t, double step = kCheckStep) const override {
    return check_residual(m_, X, t, step);
  }
  std::shared_ptr<ForceField> factored_force_field(LaneBuild build = lane_build()) const override {
    if constexpr (SeparableMotion<Motion>) return std::make_shared<FactoredForceField<Motion, Material>>(m_, build);
    else {
      (void)build;
      return nullptr;
    }
  }
  const Manufactured<Motion, Material>& manufactured() const { return m_; }

 private:
  Manufactured<Motion, Material> m_;
};

// The solution of `motion` in whichever material the scene chose.
template <class Motion>
std::shared_ptr<const ExactSolution> make_solution(const Motion& motion, const MaterialModel& material,
                                                   double density, Geometry geometry) {
  return std::visit(
      [&](const auto& m) -> std::shared_ptr<const ExactSolution> {
        using Material = std::decay_t<decltype(m)>;
        return std::make_shared<ManufacturedSolution<Motion, Material>>(motion, m, density, geometry);
      },
      material);
}

}  // namespace mpmvv::mms
