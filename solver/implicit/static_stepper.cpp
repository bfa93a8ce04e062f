#include "static_stepper.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>

#include "newton_krylov.hpp"
#include "solver/explicit_stepper.hpp"
#include "solver/shape/cpdi.hpp"
#include "solver/shape/cpdi_exact.hpp"
#include "solver/shape/gimp.hpp"
#include "solver/shape/linear.hpp"
#include "solver/monitors.hpp"
#include "solver/stages.hpp"

namespace mpmvv {

namespace {

// How a node's displacement depends on the unknowns: u = base + sum_k q[dof_k] direction_k.
struct NodeMap {
  int dof[2] = {-1, -1};
  Vec2 direction[2] = {Vec2::Zero(), Vec2::Zero()};
  Vec2 base = Vec2::Zero();
};

// What one more Newton iteration would still move (StaticStepper::remaining_correction).
struct Remaining {
  double displacement = std::numeric_limits<double>::quiet_NaN();  // mass-weighted RMS of K^-1 R [m]
  double energy = std::numeric_limits<double>::quiet_NaN();        // R^T K^-1 R, the energy norm squared
};

// Couplings a particle makes between nodes at most this many cells apart
// enter the preconditioner (farther ones, from domains stretched past two
// cells, are left out of it: it stays a preconditioner).
constexpr int kReach = 2;
constexpr int kSpan = 2 * kReach + 1;

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
    buffers_.resize(max_threads(), model_.grid.node_count());
    if (body_force_) {
      body_force_->prepare(model_.particles);
      model_.particles.body_force.assign(model_.particles.size(), Vec2::Zero());
    }
    const SmallStrainModuli m = material_.small_strain_moduli();
    moduli_ = m;
    force_scale_ = 2.0 * m.mu * model_.grid.h;
  }

  void step(double t, double dt, double) override {
    time_ = t;
    failure_.clear();
    Particles& P = model_.particles;
    const std::size_t nodes = model_.grid.node_count();
    deformation_n_ = P.deformation_gradient;
    const Shape shape = Shape::bind(model_.grid, P, deformation_n_.data());
    particles_to_grid<kMass>(shape, P, buffers_, fields_);
    if (body_force_) body_force_->evaluate(t + dt, P, P.body_force);

    // The master's motion over the step and the gap of every node (contact.hpp).
    Vec2 master_step = Vec2::Zero();
    if (contact_) {
      master_step = contact_->displacement(t + dt) - contact_->displacement(t);
      ContactScratch scratch;
      node_contact_gaps(*contact_, shape, P, model_.grid, t, 3.0 * model_.grid.h + master_step.norm(), scratch);
      gap_ = scratch.node_gap;
      if (active_.size() != nodes) active_.assign(nodes, 0);
    }

    std::vector<double> q;
    NewtonKrylovResult result;
    u_.assign(nodes, Vec2::Zero());
    for (int pass = 0;; ++pass) {
      build_map(t, dt, master_step);
      warm_start(q);
      result = solve(shape, q);
      if (!result.converged) break;
      if (!contact_ || !update_active_set(shape, q, master_step)) break;
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
      return;
    }
    finish(shape, q, dt);
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
            {"preconditioner_seconds", preconditioner_seconds_}};
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
  // ------------------------------------------------------------ unknowns

  int wall_x(int k) const { return k == 0 ? model_.grid.ghost_layers : model_.grid.nodes_x() - 1 - model_.grid.ghost_layers; }
  int wall_y(int k) const { return k == 0 ? model_.grid.ghost_layers : model_.grid.nodes_y() - 1 - model_.grid.ghost_layers; }

  // Free components of the nodes that carry mass, between the walls; the
  // walls' normal components, the constrained components and (for nodes in
  // contact) the normal component are fixed; ghost nodes mirror the nodes
  // inside.
  void build_map(double t, double dt, const Vec2& master_step) {
    const GridGeometry& grid = model_.grid;
    const int nx = grid.nodes_x(), ny = grid.nodes_y();
    map_.assign(grid.node_count(), NodeMap{});
    std::vector<unsigned char> fixed(2 * grid.node_count(), 0);
    std::vector<double> value(2 * grid.node_count(), 0.0);
    for (int j = 0; j < ny; ++j)
      for (int w = 0; w < 2; ++w) fixed[2 * std::size_t(grid.node(wall_x(w), j))] = 1;
    for (int i = 0; i < nx; ++i)
      for (int w = 0; w < 2; ++w) fixed[2 * std::size_t(grid.node(i, wall_y(w))) + 1] = 1;
    for (const NodeConstraint& c : constraints_) {
      const double increment = c.displacement(t + dt) - c.displacement(t);
      for (std::size_t node : c.nodes) {
        fixed[2 * node + std::size_t(c.axis)] = 1;
        value[2 * node + std::size_t(c.axis)] = increment;
      }
    }
    dofs_ = 0;
    for (int j = wall_y(0); j <= wall_y(1); ++j)
      for (int i = wall_x(0); i <= wall_x(1); ++i) {
        const std::size_t node = std::size_t(grid.node(i, j));
        if (!(fields_.mass[node] > 0.0)) continue;
        NodeMap& m = map_[node];
        for (int a = 0; a < 2; ++a) m.base[a] = value[2 * node + std::size_t(a)];
        if (contact_ && active_[node]) {
          // u.n = dU.n - gap: the normal part fixed, the rest free.
          const Vec2 n = contact_->normal(grid.node_position(i, j), t);
          const double c = master_step.dot(n) - gap_[node];
          const bool fx = fixed[2 * node], fy = fixed[2 * node + 1];
          if (!fx && !fy) {
            m.base = c * n;
            m.dof[0] = dofs_++;
            m.direction[0] = Vec2(-n.y(), n.x());
          } else if (fx && !fy && std::abs(n.y()) > 1e-12) {
            m.base.y() = (c - m.base.x() * n.x()) / n.y();
          } else if (fy && !fx && std::abs(n.x()) > 1e-12) {
            m.base.x() = (c - m.base.y() * n.y()) / n.x();
          }
          continue;
        }
        int k = 0;
        for (int a = 0; a < 2; ++a)
          if (!fixed[2 * node + std::size_t(a)]) {
            m.dof[k] = dofs_++;
            m.direction[k] = a == 0 ? Vec2(1.0, 0.0) : Vec2(0.0, 1.0);
            ++k;
          }
      }
    // Ghost nodes: the mirror image across the walls they lie beyond.
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        int mi = i, mj = j;
        Vec2 sign(1.0, 1.0);
        if (i < wall_x(0)) mi = 2 * wall_x(0) - i, sign.x() = -1.0;
        if (i > wall_x(1)) mi = 2 * wall_x(1) - i, sign.x() = -1.0;
        if (j < wall_y(0)) mj = 2 * wall_y(0) - j, sign.y() = -1.0;
        if (j > wall_y(1)) mj = 2 * wall_y(1) - j, sign.y() = -1.0;
        if (mi == i && mj == j) continue;
        if (mi < 0 || mi >= nx || mj < 0 || mj >= ny) continue;
        NodeMap m = map_[std::size_t(grid.node(mi, mj))];
        m.base = m.base.cwiseProduct(sign);
        for (int k = 0; k < 2; ++k) m.direction[k] = m.direction[k].cwiseProduct(sign);
        map_[std::size_t(grid.node(i, j))] = m;
      }
  }

  // The unknowns that come closest to the last displacements (zero at a
  // step's start; a contact pass starts from the pass before it).
  void warm_start(std::vector<double>& q) const {
    q.assign(std::size_t(dofs_), 0.0);
    for (std::size_t i = 0; i < map_.size(); ++i)
      for (int k = 0; k < 2; ++k)
        if (map_[i].dof[k] >= 0) q[std::size_t(map_[i].dof[k])] = (u_[i] - map_[i].base).dot(map_[i].direction[k]);
  }

  void displacements(const std::vector<double>& q, std::vector<Vec2>& u) const {
    u.resize(map_.size());
    for (std::size_t i = 0; i < map_.size(); ++i) {
      const NodeMap& m = map_[i];
      Vec2 v = m.base;
      for (int k = 0; k < 2; ++k)
        if (m.dof[k] >= 0) v += q[std::size_t(m.dof[k])] * m.direction[k];
      u[i] = v;
    }
  }

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
    displacements(q, u_);
    node_forces(shape, u_);
    std::fill(r.begin(), r.end(), 0.0);
    for (std::size_t i = 0; i < map_.size(); ++i)
      for (int k = 0; k < 2; ++k)
        if (map_[i].dof[k] >= 0) r[std::size_t(map_[i].dof[k])] -= map_[i].direction[k].dot(fields_.force[i]);
    return true;
  }

  // ------------------------------------------------------------ preconditioner

  // K = sum_p V_p B_p^T C B_p in the unknowns, with C the small-strain
  // elasticity of the material: K_ab = V (lambda g_a g_b^T + mu g_b g_a^T + mu (g_a . g_b) I).
  void assemble(const Shape& shape) {
    const auto start = std::chrono::steady_clock::now();
    const GridGeometry& grid = model_.grid;
    const std::size_t nodes = grid.node_count();
    const int nx = grid.nodes_x();
    blocks_.assign(nodes * kSpan * kSpan, Mat2::Zero());
    const Particles& P = model_.particles;
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
          const Mat2 K = V * (moduli_.lambda * ga * gb.transpose() + moduli_.mu * gb * ga.transpose() +
                              moduli_.mu * ga.dot(gb) * Mat2::Identity());
          blocks_[std::size_t(node[a]) * kSpan * kSpan + std::size_t((dj + kReach) * kSpan + di + kReach)] += K;
        }
    }
    std::vector<Eigen::Triplet<double>> triplets;
    double largest = 0.0;
    for (std::size_t a = 0; a < nodes; ++a) {
      const NodeMap& ma = map_[a];
      if (ma.dof[0] < 0 && ma.dof[1] < 0) continue;
      const int ia = int(a) % nx, ja = int(a) / nx;
      for (int dj = -kReach; dj <= kReach; ++dj)
        for (int di = -kReach; di <= kReach; ++di) {
          const Mat2& K = blocks_[a * kSpan * kSpan + std::size_t((dj + kReach) * kSpan + di + kReach)];
          if (K.isZero()) continue;
          const int ib = ia + di, jb = ja + dj;
          if (ib < 0 || jb < 0 || ib >= nx || jb >= grid.nodes_y()) continue;
          const NodeMap& mb = map_[std::size_t(grid.node(ib, jb))];
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
    for (int k = 0; k < dofs_; ++k) triplets.emplace_back(k, k, 1e-10 * largest);
    Eigen::SparseMatrix<double> K(dofs_, dofs_);
    K.setFromTriplets(triplets.begin(), triplets.end());
    factor_.compute(K);
    if (factor_.info() != Eigen::Success) throw std::runtime_error("the preconditioner's LDL^T factorization failed");
    factored_dofs_ = dof_numbering();
    preconditioner_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  NewtonKrylovResult solve(const Shape& shape, std::vector<double>& q) {
    std::vector<double> r(q.size());
    NewtonKrylovProblem problem;
    problem.residual = [&](const std::vector<double>& x, std::vector<double>& f) { return residual(shape, x, f); };
    problem.setup = [&](const std::vector<double>&) { assemble(shape); };
    problem.solve = [&](std::vector<double>& v) {
      const Eigen::Map<Eigen::VectorXd> in(v.data(), Eigen::Index(v.size()));
      const Eigen::VectorXd out = factor_.solve(in);
      std::copy(out.data(), out.data() + out.size(), v.begin());
    };
    NewtonKrylovOptions o;
    o.tolerance = options_.tolerance;
    o.force_scale = force_scale_;
    o.step_scale = model_.grid.h;
    o.max_iterations = options_.max_iterations;
    return solve_newton_krylov(problem, q, o);
  }

  // Each node's two unknowns (-1: none), as build_map numbered them.
  std::vector<int> dof_numbering() const {
    std::vector<int> dofs;
    dofs.reserve(2 * map_.size());
    for (const NodeMap& m : map_) dofs.insert(dofs.end(), {m.dof[0], m.dof[1]});
    return dofs;
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
    if (!tangent_set && factored_dofs_ != dof_numbering()) assemble(shape);
    const Eigen::Map<const Eigen::VectorXd> R(r.data(), Eigen::Index(r.size()));
    const Eigen::VectorXd c = factor_.solve(R);
    double weighted = 0.0, mass = 0.0;
    for (std::size_t i = 0; i < map_.size(); ++i) {
      if (!(fields_.mass[i] > 0.0)) continue;
      Vec2 v = Vec2::Zero();
      for (int k = 0; k < 2; ++k)
        if (map_[i].dof[k] >= 0) v += c[map_[i].dof[k]] * map_[i].direction[k];
      weighted += fields_.mass[i] * v.squaredNorm();
      mass += fields_.mass[i];
    }
    Remaining out;
    if (mass > 0.0) out.displacement = std::sqrt(weighted / mass);
    out.energy = std::abs(c.dot(R));
    return out;
  }

  // ------------------------------------------------------------ contact

  // After a solve: nodes whose contact force pulls are released, nodes that
  // would cross the master join. Returns whether the set changed.
  bool update_active_set(const Shape& shape, const std::vector<double>& q, const Vec2& master_step) {
    residual_at(shape, q);
    const GridGeometry& grid = model_.grid;
    bool changed = false;
    const double t = time_;
    for (int j = wall_y(0); j <= wall_y(1); ++j)
      for (int i = wall_x(0); i <= wall_x(1); ++i) {
        const std::size_t node = std::size_t(grid.node(i, j));
        if (!(fields_.mass[node] > 0.0) || !std::isfinite(gap_[node])) continue;
        const Vec2 n = contact_->normal(grid.node_position(i, j), t);
        if (active_[node]) {
          // The master's push on the body, -(f_ext - f_int) along n, must be positive.
          if (-fields_.force[node].dot(n) < 0.0) {
            active_[node] = 0;
            changed = true;
          }
        } else if ((u_[node] - master_step).dot(n) < -gap_[node] - 1e-12 * grid.h) {
          active_[node] = 1;
          changed = true;
        }
      }
    return changed;
  }

  void residual_at(const Shape& shape, const std::vector<double>& q) {
    std::vector<double> r(q.size());
    residual(shape, q, r);
  }

  // ------------------------------------------------------------ the step's end

  void finish(const Shape& shape, const std::vector<double>& q, double dt) {
    residual_at(shape, q);  // u_ and fields_.force at the solution
    Particles& P = model_.particles;
    // Work of the loads over the increment, by the trapezoid rule between the
    // loads at the step's start and end (energy ledger, monitors.hpp).
    const std::vector<double> previous_reactions = reactions_;
    reactions_.clear();
    for (std::size_t k = 0; k < constraints_.size(); ++k) {
      const NodeConstraint& c = constraints_[k];
      double reaction = 0.0;
      for (std::size_t node : c.nodes) reaction -= fields_.force[node][c.axis];
      reactions_.push_back(reaction);
      const double before = k < previous_reactions.size() ? previous_reactions[k] : 0.0;
      ledger_.constraints += 0.5 * (before + reaction) * (c.displacement(time_ + dt) - c.displacement(time_));
    }
    if (body_force_) {
      double work = 0.0;
      Stencil<Shape::stencil_size> s;
      for (std::size_t p = 0; p < P.size(); ++p) {
        shape.evaluate(p, s);
        Vec2 move = Vec2::Zero();
        for (int k = 0; k < s.count; ++k) move += s.weight[k] * u_[std::size_t(s.node[k])];
        const Vec2 before = previous_body_force_.empty() ? Vec2::Zero() : previous_body_force_[p];
        work += P.mass[p] * 0.5 * (before + P.body_force[p]).dot(move);
      }
      ledger_.body += work;
      previous_body_force_ = P.body_force;
    }
    if (contact_) {
      const std::vector<Vec2> previous = contact_forces_.node_force;
      contact_forces_.node_force.assign(model_.grid.node_count(), Vec2::Zero());
      contact_forces_.total.setZero();
      for (std::size_t i = 0; i < active_.size(); ++i)
        if (active_[i] && fields_.mass[i] > 0.0) {
          contact_forces_.node_force[i] = -fields_.force[i];
          contact_forces_.total += contact_forces_.node_force[i];
        }
      for (std::size_t i = 0; i < contact_forces_.node_force.size(); ++i) {
        const Vec2 before = i < previous.size() ? previous[i] : Vec2::Zero();
        ledger_.contact += 0.5 * (before + contact_forces_.node_force[i]).dot(u_[i]);
      }
    }
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
  std::optional<RigidBody> contact_;
  StaticOptions options_;
  SmallStrainModuli moduli_{};
  double force_scale_ = 1.0;
  double time_ = 0.0;

  ScatterBuffers buffers_;
  std::vector<Mat2> deformation_n_;
  std::vector<Vec2> previous_body_force_;
  std::vector<NodeMap> map_;
  int dofs_ = 0;
  std::vector<Vec2> u_;
  std::vector<Mat2> blocks_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factor_;
  std::vector<double> gap_;
  std::vector<unsigned char> active_;
  std::string failure_;
  long newton_iterations_ = 0, linear_iterations_ = 0, residual_evaluations_ = 0, solves_ = 0;
  double preconditioner_seconds_ = 0.0;
  Remaining remaining_;
  std::vector<int> factored_dofs_;  // dof_numbering() when factor_ was computed; empty before
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
