#include "static_stepper.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>

#include "active_set.hpp"
#include "load_work.hpp"
#include "newton_krylov.hpp"
#include "tangent.hpp"
#include "unknowns.hpp"
#include "solver/explicit_stepper.hpp"
#include "solver/shape/cpdi.hpp"
#include "solver/shape/cpdi_exact.hpp"
#include "solver/shape/gimp.hpp"
#include "solver/shape/linear.hpp"
#include "solver/monitors.hpp"
#include "solver/stages.hpp"

namespace mpmvv {

namespace {

// What one more Newton iteration would still move (StaticStepper::remaining_correction).
struct Remaining {
  double displacement = std::numeric_limits<double>::quiet_NaN();  // mass-weighted RMS of K^-1 R [m]
  double energy = std::numeric_limits<double>::quiet_NaN();        // R^T K^-1 R, the energy norm squared
};

// The node sums of the implicit step (particle to grid) are made by this
// many threads whatever the run's thread count: each adds its share of the
// particles into a buffer of its own and the buffers are added in order
// (solver/stages/particle_to_grid.hpp), so the sums, and every Newton solve
// built on them, have the same bits on any thread count. With the run's
// count instead, the 64-cell compressed neo-Hookean bar completed on two
// threads and stopped at t = 15.26 s on one: its solves move nodes that
// particles barely reach (a 1e-5 share of a node's mass) by up to 91 cells,
// a displacement its residual hardly constrains, so the last bits of the
// sums decided which halved load steps got through. The assembly of the
// tangent and KINSOL's vectors are serial already.
constexpr int kSumSplit = 2;

template <class Shape, class Material>
class StaticStepper final : public Stepper {
 public:
  StaticStepper(Model model, Material material, SceneStages stages, StaticOptions options)
      : Stepper(std::move(model)),
        material_(material),
        body_force_(std::move(stages.body_force)),
        constraints_(std::move(stages.constraints)),
        contact_(std::move(stages.contact)),
        options_(options) {
    buffers_.resize(kSumSplit, model_.grid.node_count());
    if (body_force_) {
      body_force_->prepare(model_.particles);
      model_.particles.body_force.assign(model_.particles.size(), Vec2::Zero());
    }
    const SmallStrainModuli m = material_.small_strain_moduli();
    moduli_ = m;
    force_scale_ = 2.0 * m.mu * model_.grid.h;
  }

  // The load step [t, t + dt], halved where its solve fails
  // (StaticOptions::max_halvings); failure_ says why the last try failed.
  void step(double t, double dt, double) override {
    failure_.clear();
    if (step_in_halves(t, dt, 0)) failure_.clear();
  }

  bool step_in_halves(double t, double dt, int depth) {
    if (solve_load_step(t, dt)) return true;
    if (depth >= options_.max_halvings) {
      if (depth > 0) failure_ += fmt::format(" (a load step of {:.3g} s, halved {} times)", dt, depth);
      return false;
    }
    ++halvings_;
    return step_in_halves(t, 0.5 * dt, depth + 1) && step_in_halves(t + 0.5 * dt, 0.5 * dt, depth + 1);
  }

  // One solve from t to t + dt; the particles move only when it converges.
  bool solve_load_step(double t, double dt) {
    time_ = t;
    failure_.clear();
    Particles& P = model_.particles;
    const std::size_t nodes = model_.grid.node_count();
    deformation_n_ = P.deformation_gradient;
    const Shape shape = Shape::bind(model_.grid, P, deformation_n_.data());
    particles_to_grid<kMass>(shape, P, buffers_, fields_);
    if (body_force_) body_force_->evaluate(t + dt, P, P.body_force);

    contact_.start_step(shape, P, model_.grid, t, dt);

    std::vector<double> q;
    NewtonKrylovResult result;
    u_.assign(nodes, Vec2::Zero());
    for (int pass = 0;; ++pass) {
      unknowns_.build(model_.grid, fields_.mass, constraints_, contact_.unknowns(), t, dt);
      unknowns_.closest(u_, q);
      result = solve(shape, q);
      if (!result.converged) break;
      if (!contact_.has_master()) break;
      residual_at(shape, q);  // u_ and fields_.force at the solution
      if (!contact_.update(model_.grid, fields_, u_)) break;
      if (pass + 1 >= options_.max_contact_passes) {
        failure_ = fmt::format("contact active set still changing after {} passes", options_.max_contact_passes);
        break;
      }
    }
    newton_iterations_ += result.iterations;
    if (result.converged) remaining_ = remaining_correction(shape, q, result.preconditioner_setups > 0);
    linear_iterations_ += result.linear_iterations;
    residual_evaluations_ += result.residual_evaluations;
    ++solves_;
    if (!result.converged) {
      failure_ = fmt::format("KINSOL: {} after {} Newton iterations (|R| / (2 mu h) = {:.3g})",
                             result.message, result.iterations, result.residual_norm);
      return false;
    }
    if (!failure_.empty()) return false;  // the contact's active set kept changing
    finish(shape, q, dt);
    return true;
  }

  std::string step_failure() const override { return failure_; }

  // The last solve's remaining Newton correction c (remaining_correction). Its
  // strain e over the body: c . R = c^T K c is the strain energy of c, and
  // small-strain elasticity stores at least mu |e|^2 per volume (lambda >= 0),
  // so the RMS of |e| over the body's volume V is at most sqrt(c . R / (2 mu V))
  // (energy per unit depth, twice the stored energy).
  Settling distance_to_equilibrium(double shear_modulus) const override {
    const double volume = std::accumulate(model_.particles.volume.begin(), model_.particles.volume.end(), 0.0);
    return {remaining_.displacement, std::sqrt(remaining_.energy / (2.0 * shear_modulus * volume))};
  }

  std::vector<std::pair<std::string, double>> statistics() const override {
    return {{"implicit_solves", double(solves_)},
            {"newton_iterations", double(newton_iterations_)},
            {"gmres_iterations", double(linear_iterations_)},
            {"residual_evaluations", double(residual_evaluations_)},
            {"load_step_halvings", double(halvings_)},
            {"preconditioner_seconds", tangent_.seconds()}};
  }

  ParticleScan scan() const override {
    return scan_particles(Shape::bind(model_.grid, model_.particles), material_, model_.particles, model_.grid.h);
  }

  Monitors monitors() const override {
    return monitor_particles(Shape::bind(model_.grid, model_.particles), material_, model_.particles, model_.grid);
  }

  ParticleFault diagnose(std::size_t p) const override {
    const Particles& P = model_.particles;
    const Vec2& x = P.position[p];
    if (!(x.allFinite() && P.deformation_gradient[p].allFinite() && P.stress[p].allFinite()))
      return {"nan", fmt::format("non-finite state at x = ({:.6g}, {:.6g})", x.x(), x.y())};
    const double J = determinant(P.deformation_gradient[p]);
    if (!(J > 0.0)) return {"non-positive J", fmt::format("J = {:.6g} at x = ({:.6g}, {:.6g})", J, x.x(), x.y())};
    return {"outside grid", fmt::format("the particle at ({:.6g}, {:.6g}) or its domain left the grid", x.x(), x.y())};
  }

 private:
  // ------------------------------------------------------------ residual

  // dF = I + sum_g u_g (x) G_gp over a particle's stencil.
  static Mat2 increment(const Stencil<Shape::stencil_size>& s, const std::vector<Vec2>& u) {
    Mat2 dF = Mat2::Identity();
    for (int k = 0; k < s.count; ++k) dF += u[std::size_t(s.node[k])] * s.gradient[k].transpose();
    return dF;
  }

  // The node sums -(f_int - f_ext) at the trial displacements: trial first
  // Piola stresses in P.stress (P.volume is V^n throughout the solve).
  void node_forces(const Shape& shape, const std::vector<Vec2>& u) {
    Particles& P = model_.particles;
    const std::size_t n = P.size();
#pragma omp parallel
    {
      Stencil<Shape::stencil_size> s;
#pragma omp for schedule(static)
      for (std::size_t p = 0; p < n; ++p) {
        shape.evaluate(p, s);
        const Mat2 dF = increment(s, u);
        const Mat2 F = dF * deformation_n_[p];
        const Mat2 sigma = material_.cauchy_stress(F);
        P.stress[p] = determinant(dF) * sigma * inverse(dF).transpose();
      }
    }
    if (body_force_) particles_to_grid<kInternalForce | kBodyForce>(shape, P, buffers_, fields_);
    else particles_to_grid<kInternalForce>(shape, P, buffers_, fields_);
  }

  bool residual(const Shape& shape, const std::vector<double>& q, std::vector<double>& r) {
    unknowns_.displacements(q, u_);
    node_forces(shape, u_);
    std::fill(r.begin(), r.end(), 0.0);
    unknowns_.subtract_forces(fields_.force, r);
    return true;
  }

  NewtonKrylovResult solve(const Shape& shape, std::vector<double>& q) {
    std::vector<double> r(q.size());
    NewtonKrylovProblem problem;
    problem.residual = [&](const std::vector<double>& x, std::vector<double>& f) { return residual(shape, x, f); };
    problem.setup = [&](const std::vector<double>&) { assemble(shape); };
    problem.solve = [&](std::vector<double>& v) {
      const Eigen::Map<Eigen::VectorXd> in(v.data(), Eigen::Index(v.size()));
      const Eigen::VectorXd out = tangent_.solve(in);
      std::copy(out.data(), out.data() + out.size(), v.begin());
    };
    NewtonKrylovOptions o;
    o.tolerance = options_.tolerance;
    o.force_scale = force_scale_;
    o.step_scale = model_.grid.h;
    o.max_iterations = options_.max_iterations;
    return solve_newton_krylov(problem, q, o);
  }

  void assemble(const Shape& shape) {
    tangent_.assemble(shape, model_.particles, model_.grid, moduli_, unknowns_);
  }

  // How far the solution q still is from equilibrium: the Newton correction
  // c = K^-1 R(q) one more iteration would start from, K the preconditioner's
  // tangent; its mass-weighted RMS over the nodes [m] and its energy norm
  // squared, c . R (Newton's error after its last step is of the order of
  // that step's square, so the last step taken is no such estimate; the mass
  // weights leave out the nodes particles barely reach, whose stiffness is the
  // factorization's regularization). A solve that took no iteration (a load
  // step at full load whose start is already in equilibrium) set no tangent
  // up: the last one stands in for it where it numbers the same unknowns (an
  // estimate either way; assembling and factorizing afresh cost a third of the
  // uniaxial bar's run).
  Remaining remaining_correction(const Shape& shape, const std::vector<double>& q, bool tangent_set) {
    std::vector<double> r(q.size());
    residual(shape, q, r);
    if (!tangent_set && !tangent_.serves(unknowns_)) assemble(shape);
    const Eigen::Map<const Eigen::VectorXd> R(r.data(), Eigen::Index(r.size()));
    const Eigen::VectorXd c = tangent_.solve(R);
    std::vector<Vec2> correction;
    unknowns_.displacements(c, correction, false);
    double weighted = 0.0, mass = 0.0;
    for (std::size_t i = 0; i < correction.size(); ++i) {
      if (!(fields_.mass[i] > 0.0)) continue;
      weighted += fields_.mass[i] * correction[i].squaredNorm();
      mass += fields_.mass[i];
    }
    Remaining out;
    if (mass > 0.0) out.displacement = std::sqrt(weighted / mass);
    out.energy = std::abs(c.dot(R));
    return out;
  }

  void residual_at(const Shape& shape, const std::vector<double>& q) {
    std::vector<double> r(q.size());
    residual(shape, q, r);
  }

  // ------------------------------------------------------------ the step's end

  void finish(const Shape& shape, const std::vector<double>& q, double dt) {
    residual_at(shape, q);  // u_ and fields_.force at the solution
    Particles& P = model_.particles;
    // The work of the loads over the step (load_work.hpp).
    book_constraint_work(constraints_, fields_, time_, dt, reactions_, ledger_);
    if (body_force_) book_body_force_work(shape, P, u_, previous_body_force_, ledger_);
    if (contact_.has_master()) book_contact_work(contact_.active(), fields_, u_, contact_forces_, ledger_);
    // Tracers move with the grid's displacement, as in the explicit step
    // (mass-weighted, stages.hpp).
    if (!model_.tracers.empty()) {
      for (std::size_t i = 0; i < u_.size(); ++i) fields_.velocity[i] = u_[i] / dt;
      advect_tracers(model_.grid, fields_, model_.tracers, dt);
    }
    const std::size_t n = P.size();
#pragma omp parallel
    {
      Stencil<Shape::stencil_size> s;
#pragma omp for schedule(static)
      for (std::size_t p = 0; p < n; ++p) {
        shape.evaluate(p, s);
        const Mat2 dF = increment(s, u_);
        Vec2 move = Vec2::Zero();
        for (int k = 0; k < s.count; ++k) move += s.weight[k] * u_[std::size_t(s.node[k])];
        P.deformation_gradient[p] = dF * deformation_n_[p];
        P.volume[p] = determinant(P.deformation_gradient[p]) * P.reference_volume[p];
        P.stress[p] = material_.cauchy_stress(P.deformation_gradient[p]);
        P.position[p] += move;
        P.velocity[p].setZero();  // quasi-static: no inertia, no kinetic energy
      }
    }
  }

  Material material_;
  std::shared_ptr<BodyForce> body_force_;
  std::vector<NodeConstraint> constraints_;
  ActiveContactSet contact_;
  StaticOptions options_;
  SmallStrainModuli moduli_{};
  double force_scale_ = 1.0;
  double time_ = 0.0;

  ScatterBuffers buffers_;
  std::vector<Mat2> deformation_n_;
  std::vector<Vec2> previous_body_force_;
  GridUnknowns unknowns_;
  std::vector<Vec2> u_;  // the node displacements of the last residual's unknowns
  SmallStrainTangent tangent_;
  std::string failure_;
  long halvings_ = 0;  // load steps taken again as two halves (step_in_halves)
  long newton_iterations_ = 0, linear_iterations_ = 0, residual_evaluations_ = 0, solves_ = 0;
  Remaining remaining_;
};

template <class Shape>
std::unique_ptr<Stepper> make_for_shape(Model model, const MaterialModel& material, SceneStages stages,
                                        const StaticOptions& o) {
  return std::visit(
      [&](const auto& m) -> std::unique_ptr<Stepper> {
        using Material = std::decay_t<decltype(m)>;
        return std::make_unique<StaticStepper<Shape, Material>>(std::move(model), m, std::move(stages), o);
      },
      material);
}

}  // namespace

std::unique_ptr<Stepper> make_static_stepper(Model model, const SolverOptions& options, const MaterialModel& material,
                                             SceneStages stages, const StaticOptions& o) {
  if (options.geometry != Geometry::plane_strain)
    throw std::invalid_argument("the implicit static step is plane strain only");
  if (options.fault != SolverFault::none)
    throw std::invalid_argument(fmt::format("the deliberate fault {} is injected into the explicit step only",
                                            to_string(options.fault)));
  if (model.particles.size() == 0) throw std::invalid_argument("the scene seeded no particles");
  if (options.method == Method::bspline || options.method == Method::bspline_cubic)
    throw std::invalid_argument(fmt::format("method {} serves the explicit step only", to_string(options.method)));
  if (options.method != Method::linear && model.particles.half_size.size() != model.particles.size())
    throw std::invalid_argument(fmt::format("method {} needs a particle domain (half_size) for every particle",
                                            to_string(options.method)));
  check_domain_outlines(model.particles, options.method);
  if (options.split_domains_beyond != 0.0)
    throw std::invalid_argument("split_domains_beyond serves the explicit step only");
  if (options.min_domain_angle != 0.0)
    throw std::invalid_argument("min_domain_angle serves the explicit step only");
  if (options.cpdi_domain != CpdiDomain::convected)
    throw std::invalid_argument("cpdi_domain = corners serves the explicit step only");
  if (options.dilatation != Dilatation::particle)
    throw std::invalid_argument("the dilatation remedies (cell-averaged, node-smoothed) serve the explicit step only");
  if (options.bulk_viscosity_linear != 0.0 || options.bulk_viscosity_quadratic != 0.0)
    throw std::invalid_argument("bulk viscosity serves the explicit step only (a static step has no rate)");
  if (options.formulation != Formulation::updated)
    throw std::invalid_argument("the implicit static step has the updated formulation only");
  if (options.velocity_transfer != VelocityTransfer::flip)
    throw std::invalid_argument("velocity_transfer = apic serves the explicit step only (a static step has no velocities)");
  if (stages.second_material)
    throw std::invalid_argument("a second material serves the explicit step only");
  if (!stages.rest_points.empty())
    throw std::invalid_argument("rest points serve the explicit step only (rims = \"held\" holds the nodes)");
  if (stages.traction) throw std::invalid_argument("boundary tractions serve the explicit step only");
  switch (options.method) {
    case Method::linear: return make_for_shape<LinearShape>(std::move(model), material, std::move(stages), o);
    case Method::gimp: return make_for_shape<GimpShapeT<Geometry::plane_strain>>(std::move(model), material, std::move(stages), o);
    case Method::cpdi: return make_for_shape<CpdiShape>(std::move(model), material, std::move(stages), o);
    case Method::cpdi_exact: return make_for_shape<CpdiExactShape>(std::move(model), material, std::move(stages), o);
    case Method::bspline:
    case Method::bspline_cubic: break;  // refused above
  }
  throw std::logic_error("unknown method");
}

}  // namespace mpmvv
