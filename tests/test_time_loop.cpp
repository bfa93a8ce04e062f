// The time loop (solver/time_loop.hpp) around the explicit step: failures
// reported as data, output times landed on within the CFL step, a step
// prepared by its map, a stage that gives up, a run stopped by a signal and
// resumed.
#include <gtest/gtest.h>

#include "solver_models.hpp"
#include "support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "solver/explicit_stepper.hpp"
#include "solver/io/state_archive.hpp"
#include "solver/parallel.hpp"
#include "solver/domain_angle.hpp"
#include "solver/domain_corners.hpp"
#include <map>
#include "solver/shape/cpdi.hpp"
#include "solver/split.hpp"
#include "solver/time_loop.hpp"

namespace {

using namespace mpmvv::testing::solver_models;  // the models and the solver's names they use

// ---------------------------------------------------------------- failures as data


// A particle that starts outside the grid, one with det F <= 0 and one with a
// NaN velocity each stop the run before the first step, as data: the reason,
// time 0, step 0 and the particle's index.
TEST(TimeLoop, BadInitialParticleIsReportedAsData) {
  struct Case {
    const char* reason;
    void (*spoil)(Particles&, std::size_t);
  };
  const Case cases[] = {
      {"outside grid", [](Particles& P, std::size_t p) { P.position[p] = Vec2(2.5, 0.0); }},
      {"non-positive J",
       [](Particles& P, std::size_t p) { P.deformation_gradient[p] = Vec2(1.0, -1.0).asDiagonal(); }},
      {"nan", [](Particles& P, std::size_t p) { P.velocity[p].x() = std::numeric_limits<double>::quiet_NaN(); }},
  };
  for (Method method : kMethods)
    for (const Case& c : cases) {
      SCOPED_TRACE(std::string(to_string(method)) + ": " + c.reason);
      Model model = disk_model(method);
      const std::size_t bad = model.particles.size() / 3;
      c.spoil(model.particles, bad);
      auto stepper = mpmvv::make_stepper(std::move(model), SolverOptions{method, Scheme::usl},
                                         MaterialModel{kSolid}, nullptr);
      NullObserver observer;
      const mpmvv::RunOutcome o = mpmvv::run_time_loop(*stepper, short_run(0.1), observer);
      EXPECT_FALSE(o.completed);
      EXPECT_EQ(o.failure_reason, c.reason);
      EXPECT_FALSE(o.failure_detail.empty());
      EXPECT_EQ(o.failure_time, 0.0);
      EXPECT_EQ(o.failure_step, 0);
      EXPECT_EQ(o.failure_particle, static_cast<long long>(bad));
      EXPECT_EQ(o.steps, 0);
      EXPECT_EQ(o.time_reached, 0.0);
      EXPECT_EQ(o.outputs_written, 0u);
    }
}

// Exact CPDI's stencil holds 3 x 3 cells: a particle stretched beyond them
// stops the run with its own reason, not as "outside grid".
TEST(TimeLoop, ExactCpdiDomainBeyondItsStencilIsReportedAsTooWide) {
  Model model = disk_model(Method::cpdi_exact);
  const std::size_t bad = model.particles.size() / 3;
  model.particles.deformation_gradient[bad] = Vec2(14.0, 1.0 / 14.0).asDiagonal();  // 7 cells long
  auto stepper = mpmvv::make_stepper(std::move(model), SolverOptions{Method::cpdi_exact, Scheme::usl},
                                     MaterialModel{kSolid}, nullptr);
  NullObserver observer;
  const mpmvv::RunOutcome o = mpmvv::run_time_loop(*stepper, short_run(0.1), observer);
  EXPECT_FALSE(o.completed);
  EXPECT_EQ(o.failure_reason, "domain too wide");
  EXPECT_EQ(o.failure_particle, static_cast<long long>(bad));
}

// A body force that turns NaN for one lone particle from t = 0.2 s on.
class PoisonAfter final : public mpmvv::BodyForce {
 public:
  PoisonAfter(std::size_t particle, double time) : particle_(particle), time_(time) {}
  void evaluate(double t, const Particles& P, std::vector<Vec2>& b) const override {
    std::fill(b.begin(), b.begin() + std::ptrdiff_t(P.size()), Vec2::Zero());
    if (t >= time_) b[particle_] = Vec2(std::numeric_limits<double>::quiet_NaN(), 0.0);
  }

 private:
  std::size_t particle_;
  double time_;
};

// A particle that goes bad during the run stops it at the end of that step:
// failure_time is the time that step reached and failure_step its number.
TEST(TimeLoop, FailureDuringTheRunRecordsTimeAndStep) {
  for (Method method : kMethods) {
    SCOPED_TRACE(to_string(method));
    Model model = disk_model(method);
    add_particle(model, method, Vec2(1.5, 1.5));  // far from the disk: only it is poisoned
    const std::size_t lone = model.particles.size() - 1;
    auto stepper = mpmvv::make_stepper(std::move(model), SolverOptions{method, Scheme::usl},
                                       MaterialModel{kSolid}, std::make_shared<PoisonAfter>(lone, 0.2));
    StepTimes observer;
    const mpmvv::RunOutcome o = mpmvv::run_time_loop(*stepper, short_run(1.0), observer);
    EXPECT_FALSE(o.completed);
    EXPECT_EQ(o.failure_reason, "nan");
    EXPECT_EQ(o.failure_particle, static_cast<long long>(lone));
    const std::size_t n = observer.times.size();
    ASSERT_GE(n, 3u);
    // The first step that starts at t >= 0.2 s is the last one taken.
    EXPECT_EQ(o.failure_step, static_cast<long long>(n));
    EXPECT_EQ(o.steps, o.failure_step);
    EXPECT_EQ(o.failure_time, observer.times.back());
    EXPECT_EQ(o.time_reached, o.failure_time);
    EXPECT_GE(observer.times[n - 2], 0.2);
    EXPECT_LT(observer.times[n - 3], 0.2);
  }
}

// ---------------------------------------------------------------- time loop

// Passes every call to a real stepper and records what the time loop asked
// for, with the CFL bound at that moment.
class RecordingStepper final : public Stepper {
 public:
  struct Call {
    double t, dt, kick, cfl_bound;
  };

  RecordingStepper(std::unique_ptr<Stepper> inner, double cfl)
      : Stepper(inner->model()), inner_(std::move(inner)), cfl_(cfl) {}

  void step(double t, double dt, double kick) override {
    const double bound = cfl_ * inner_->model().grid.h / inner_->scan().max_signal_speed;
    calls.push_back({t, dt, kick, bound});
    inner_->step(t, dt, kick);
  }
  mpmvv::ParticleScan scan() const override { return inner_->scan(); }
  mpmvv::ParticleFault diagnose(std::size_t p) const override { return inner_->diagnose(p); }
  mpmvv::Monitors monitors() const override { return inner_->monitors(); }

  std::vector<Call> calls;

 private:
  std::unique_ptr<Stepper> inner_;
  double cfl_;
};

class OutputTimes final : public mpmvv::RunObserver {
 public:
  void at_output(std::size_t index, double t, const Stepper&) override { outputs.emplace_back(index, t); }
  std::vector<std::pair<std::size_t, double>> outputs;
};

// The loop lands exactly on every output time, never takes a step longer
// than cfl h / max(c + |v|), passes each step the time the last one reached,
// and kicks by dt/2 first and by the mean of adjacent steps after
// (central differences).
TEST(TimeLoop, LandsOnOutputTimesWithinTheCflStep) {
  Model model = disk_model(Method::gimp);
  for (std::size_t p = 0; p < model.particles.size(); ++p) {
    const Vec2 x = model.particles.position[p];
    model.particles.velocity[p] = Vec2(0.4 * x.y(), -0.3 * x.x());
  }
  mpmvv::TimeLoopOptions options;
  options.cfl = 0.4;
  options.end_time = 0.5;
  options.output_times = {0.03, 0.1, 1.0 / 3.0, 0.35, 0.5};
  auto inner = mpmvv::make_stepper(std::move(model), SolverOptions{Method::gimp, Scheme::usl},
                                   MaterialModel{kSolid}, nullptr);
  RecordingStepper stepper(std::move(inner), options.cfl);
  OutputTimes observer;
  const mpmvv::RunOutcome o = mpmvv::run_time_loop(stepper, options, observer);

  ASSERT_TRUE(o.completed) << o.failure_reason;
  EXPECT_EQ(o.time_reached, options.end_time);
  EXPECT_EQ(o.outputs_written, options.output_times.size());
  ASSERT_EQ(observer.outputs.size(), options.output_times.size());
  for (std::size_t k = 0; k < observer.outputs.size(); ++k) {
    EXPECT_EQ(observer.outputs[k].first, k);
    EXPECT_EQ(observer.outputs[k].second, options.output_times[k]);
  }
  ASSERT_EQ(stepper.calls.size(), std::size_t(o.steps));
  double reached = 0.0;
  for (std::size_t k = 0; k < stepper.calls.size(); ++k) {
    const RecordingStepper::Call& c = stepper.calls[k];
    SCOPED_TRACE("step " + std::to_string(k));
    EXPECT_LE(c.dt, c.cfl_bound);
    EXPECT_GT(c.dt, 0.0);
    EXPECT_EQ(c.t, reached);
    const double expected_kick = k == 0 ? 0.5 * c.dt : 0.5 * (stepper.calls[k - 1].dt + c.dt);
    EXPECT_EQ(c.kick, expected_kick);
    const auto landing = std::find_if(options.output_times.begin(), options.output_times.end(),
                                      [&](double target) { return std::abs(c.t + c.dt - target) < 1e-12; });
    reached = landing != options.output_times.end() ? *landing : c.t + c.dt;
  }
  // Landing never leaves a sliver: the output times here are at least half a
  // CFL step apart, and the loop splits a last stretch shorter than two steps
  // in two, so no step is shorter than a quarter of the CFL step.
  for (const RecordingStepper::Call& c : stepper.calls) EXPECT_GT(c.dt, 0.25 * c.cfl_bound);
}

// The scan a step's map makes (Stepper::prepare_step, stages.hpp: ScanInMap)
// is the scan of the state, bit for bit, and the step it prepares moves every
// particle as a step that maps for itself. The disk is sheared (F = [[1, 4],
// [0, 1]]) so that CPDI's domains span four cells and its full stencils, whose
// repeated nodes the stiffening merges, set the speed; under USL and MUSL, the
// schemes that map first. A particle that stops the run is the same lowest one.
TEST(TimeLoop, AStepPreparedByItsMapScansAndMovesAsOneThatMapsItself) {
  for (Scheme scheme : {Scheme::usl, Scheme::musl}) {
    SCOPED_TRACE(to_string(scheme));
    Model model = disk_model(Method::cpdi);
    Mat2 F;
    F << 1.0, 4.0, 0.0, 1.0;
    double bare = 0.0;  // max_p c_p + |v_p|, without CPDI's stiffening
    for (std::size_t p = 0; p < model.particles.size(); ++p) {
      const Vec2 x = model.particles.position[p];
      model.particles.velocity[p] = Vec2(0.4 * x.y(), -0.3 * x.x());
      model.particles.deformation_gradient[p] = F;
      model.particles.stress[p] = kSolid.cauchy_stress(F);
      bare = std::max(bare, std::sqrt(kSolid.wave_modulus(F, model.particles.stress[p]) / kDensity) +
                                model.particles.velocity[p].norm());
    }
    const SolverOptions options{Method::cpdi, scheme};
    auto prepared = mpmvv::make_stepper(model, options, MaterialModel{kSolid}, nullptr);
    auto plain = mpmvv::make_stepper(model, options, MaterialModel{kSolid}, nullptr);
    double t = 0.0;
    for (int k = 0; k < 4; ++k) {
      SCOPED_TRACE("step " + std::to_string(k));
      const mpmvv::ParticleScan full = plain->scan();
      const mpmvv::ParticleScan mapped = prepared->prepare_step(t);
      EXPECT_EQ(mapped.max_signal_speed, full.max_signal_speed);
      ASSERT_EQ(mapped.first_unhealthy, model.particles.size());
      ASSERT_EQ(full.first_unhealthy, model.particles.size());
      // The stiffening sets the speed (3.16 against max c + |v| = 3.12 m/s):
      // the stencils took part.
      if (k == 0) {
        EXPECT_GT(full.max_signal_speed, bare);
      }
      const double dt = 0.4 * model.grid.h / full.max_signal_speed;
      prepared->step(t, dt, dt);
      plain->step(t, dt, dt);
      t += dt;
    }
    const Particles& a = prepared->model().particles;
    const Particles& b = plain->model().particles;
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t p = 0; p < a.size(); ++p) {
      ASSERT_TRUE(a.position[p] == b.position[p]) << "particle " << p;
      ASSERT_TRUE(a.velocity[p] == b.velocity[p]) << "particle " << p;
      ASSERT_TRUE(a.deformation_gradient[p] == b.deformation_gradient[p]) << "particle " << p;
      ASSERT_TRUE(a.stress[p] == b.stress[p]) << "particle " << p;
    }

    Model broken = model;
    broken.particles.velocity[9].x() = std::numeric_limits<double>::quiet_NaN();
    broken.particles.deformation_gradient[4] << -0.5, 0.0, 0.0, 0.5;  // J = -0.25
    auto stopped = mpmvv::make_stepper(broken, options, MaterialModel{kSolid}, nullptr);
    EXPECT_EQ(stopped->scan().first_unhealthy, 4u);
    EXPECT_EQ(stopped->prepare_step(0.0).first_unhealthy, 4u);
    broken.particles.deformation_gradient[4] = F;
    broken.particles.stress[12](1, 0) = std::numeric_limits<double>::infinity();
    auto nan = mpmvv::make_stepper(broken, options, MaterialModel{kSolid}, nullptr);
    EXPECT_EQ(nan->scan().first_unhealthy, 9u);
    EXPECT_EQ(nan->prepare_step(0.0).first_unhealthy, 9u);
    broken.particles.velocity[9].x() = 0.0;
    auto infinite = mpmvv::make_stepper(broken, options, MaterialModel{kSolid}, nullptr);
    EXPECT_EQ(infinite->scan().first_unhealthy, 12u);
    EXPECT_EQ(infinite->prepare_step(0.0).first_unhealthy, 12u);
  }
}

// A stepper whose stage gives up at its third step, as a system of rest
// points that does not factor does.
class GivingUpStepper final : public Stepper {
 public:
  explicit GivingUpStepper(std::unique_ptr<Stepper> inner) : Stepper(inner->model()), inner_(std::move(inner)) {}
  void step(double t, double dt, double kick) override {
    if (++steps_ == 3) throw std::runtime_error("rest points: the constraint system could not be factored");
    inner_->step(t, dt, kick);
  }
  mpmvv::ParticleScan scan() const override { return inner_->scan(); }
  mpmvv::ParticleFault diagnose(std::size_t p) const override { return inner_->diagnose(p); }
  mpmvv::Monitors monitors() const override { return inner_->monitors(); }

 private:
  std::unique_ptr<Stepper> inner_;
  int steps_ = 0;
};

// A stage that cannot go on ends the run as failed with the stage's message,
// at the time the last whole step reached, and the loop returns what it has
// (an exception escaping the run would lose the results file).
TEST(TimeLoop, AStageThatGivesUpEndsTheRunAsFailed) {
  auto inner = mpmvv::make_stepper(disk_model(Method::linear), SolverOptions{Method::linear, Scheme::usl},
                                   MaterialModel{kSolid}, nullptr);
  GivingUpStepper stepper(std::move(inner));
  NullObserver observer;
  const mpmvv::RunOutcome o = mpmvv::run_time_loop(stepper, short_run(0.5), observer);
  EXPECT_FALSE(o.completed);
  EXPECT_EQ(o.failure_reason, "stage failed");
  EXPECT_NE(o.failure_detail.find("could not be factored"), std::string::npos) << o.failure_detail;
  EXPECT_EQ(o.steps, 2);
  EXPECT_EQ(o.failure_step, 2);
  EXPECT_GT(o.time_reached, 0.0);
  EXPECT_EQ(o.failure_time, o.time_reached);
}

// Stops the run as a signal would (stop_request), after a given step.
class StopAfter final : public mpmvv::RunObserver {
 public:
  explicit StopAfter(int steps) : steps_(steps) {}
  void after_step(double, const Stepper&) override {
    if (++seen_ == steps_) mpmvv::stop_request().store(true);
  }

 private:
  int steps_, seen_ = 0;
};

// A run stopped between two steps saves its state once (Checkpoints), and a
// stepper built afresh that reads it goes on to the bits of a run that never
// stopped: every particle array, the step count and the time steps. CPDI with
// its domains split when they grow long (the particle count grows), under the
// stable time-step rule (the loop's own measurements are state too).
TEST(TimeLoop, ARunStoppedBySignalSavesItsStateAndGoesOnFromIt) {
  SolverOptions options{Method::cpdi, Scheme::usl};
  options.split_domains_beyond = 0.6;
  auto make = [&] {
    Model model = disk_model(Method::cpdi, 16);
    for (std::size_t p = 0; p < model.particles.size(); ++p) {
      const Vec2 x = model.particles.position[p];
      model.particles.velocity[p] = Vec2(-3.0 * x.y(), 3.0 * x.x());
    }
    return mpmvv::make_stepper(std::move(model), options, MaterialModel{kSolid}, nullptr);
  };
  mpmvv::TimeLoopOptions loop = short_run(0.3);
  loop.output_times = {0.1, 0.2, 0.3};
  loop.step_rule = mpmvv::TimeStepRule::stable;
  loop.track_every = 4;

  auto whole = make();
  NullObserver none;
  const mpmvv::RunOutcome reference = mpmvv::run_time_loop(*whole, loop, none);
  ASSERT_TRUE(reference.completed) << reference.failure_reason;
  ASSERT_GT(whole->model().particles.size(), make()->model().particles.size()) << "no domain was split";
  ASSERT_GE(reference.steps, 6);
  const int stop_after = int(reference.steps / 2);

  const std::string path = (std::filesystem::temp_directory_path() / "mpmvv-loop-state.h5").string();
  int saves = 0;
  mpmvv::LoopState saved;
  mpmvv::Checkpoints checkpoints;
  auto first = make();
  checkpoints.save = [&](const mpmvv::LoopState& state) {
    ++saves;
    saved = state;
    mpmvv::h5::File file = mpmvv::h5::File::create(path);
    {
      mpmvv::StateArchive a = mpmvv::StateArchive::writing(file.root());
      first->persist(a);
    }
    file.save();
  };
  StopAfter stop(stop_after);
  const mpmvv::RunOutcome stopped = mpmvv::run_time_loop(*first, loop, stop, {}, 1.0, checkpoints);
  mpmvv::stop_request().store(false);
  EXPECT_EQ(stopped.failure_reason, mpmvv::kInterrupted);
  EXPECT_EQ(saves, 1);
  EXPECT_EQ(saved.steps, stop_after);
  EXPECT_EQ(saved.t, stopped.time_reached);

  auto second = make();
  {
    const mpmvv::h5::File file = mpmvv::h5::File::open_read(path);
    mpmvv::StateArchive a = mpmvv::StateArchive::reading(file.root());
    second->persist(a);
  }
  mpmvv::Checkpoints going_on;
  going_on.resume = &saved;
  const mpmvv::RunOutcome resumed = mpmvv::run_time_loop(*second, loop, none, {}, 1.0, going_on);
  ASSERT_TRUE(resumed.completed) << resumed.failure_reason;
  EXPECT_EQ(resumed.steps, reference.steps);
  EXPECT_EQ(resumed.particle_steps, reference.particle_steps);
  EXPECT_EQ(resumed.dt_min, reference.dt_min);
  EXPECT_EQ(resumed.dt_max, reference.dt_max);
  EXPECT_EQ(resumed.frequency_measurements, reference.frequency_measurements);
  EXPECT_EQ(resumed.resumed_at, std::vector<double>{saved.t});
  const Particles& a = whole->model().particles;
  const Particles& b = second->model().particles;
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t p = 0; p < a.size(); ++p) {
    EXPECT_EQ(a.position[p], b.position[p]) << p;
    EXPECT_EQ(a.velocity[p], b.velocity[p]) << p;
    EXPECT_EQ(a.deformation_gradient[p], b.deformation_gradient[p]) << p;
    EXPECT_EQ(a.stress[p], b.stress[p]) << p;
    EXPECT_EQ(a.half_size[p], b.half_size[p]) << p;
  }
  std::filesystem::remove(path);
}

// Output times that do not end at the end time are refused before any step.
TEST(TimeLoop, OutputTimesMustEndAtTheEndTime) {
  auto stepper = mpmvv::make_stepper(disk_model(Method::linear), SolverOptions{Method::linear, Scheme::usl},
                                     MaterialModel{kSolid}, nullptr);
  mpmvv::TimeLoopOptions options = short_run(0.5);
  options.output_times = {0.25};
  NullObserver observer;
  EXPECT_THROW(mpmvv::run_time_loop(*stepper, options, observer), std::invalid_argument);
}


}  // namespace
