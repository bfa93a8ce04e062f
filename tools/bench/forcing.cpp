// Cost of the manufactured body force: nanoseconds per evaluation for every
// manufactured problem, derived by automatic differentiation (as a run takes
// it: the field of derived_force_field, which keeps each point's factors of X
// where the motion is separable, and point by point as
// ExactSolution::body_forces gives it) and in closed form, on one thread;
// then the 256-cell ring run with CPDI with either force, with the forcing
// time as a share of the run and per particle-step beside the solver's own
// cost.
//
//   mpmvv-bench-forcing [--points 200000] [--cells 256] [--end-time 0.1] [--threads 2]
#include <CLI/CLI.hpp>

#include <chrono>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "mms/exact_solution.hpp"
#include "mms/ring.hpp"
#include "solver/parallel.hpp"
#include "tools/app/scene/setup.hpp"

namespace {

using Clock = std::chrono::steady_clock;

// Reference points of the scene's body, uniformly at random.
std::vector<mpmvv::Vec2> body_points(const mpmvv::app::SceneSetup& s, std::size_t count) {
  std::mt19937 rng(3);
  const mpmvv::Vec2 lo = s.grid.wall_lower(), hi = s.grid.wall_upper();
  std::uniform_real_distribution<double> ux(lo.x(), hi.x()), uy(lo.y(), hi.y());
  std::vector<mpmvv::Vec2> X;
  while (X.size() < count) {
    const mpmvv::Vec2 p(ux(rng), uy(rng));
    if (s.contains(p) && p.x() > 1e-3) X.push_back(p);
  }
  return X;
}

// The best of three evaluations at all points, by the field (prepared first)
// or, without one, point by point.
double nanoseconds_per_evaluation(const mpmvv::app::SceneSetup& s, const std::vector<mpmvv::Vec2>& X,
                                  const std::shared_ptr<mpmvv::mms::ForceField>& field) {
  std::vector<mpmvv::Vec2> b(X.size());
  if (field) field->prepare(X);
  double best = 1e300;
  for (int r = 0; r < 3; ++r) {
    const auto start = Clock::now();
    if (field) field->evaluate(0.37, b);
    else s.solution->body_forces(0.37, X, b);
    best = std::min(best, std::chrono::duration<double>(Clock::now() - start).count());
  }
  return 1e9 * best / double(X.size());
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Cost of the manufactured body force, per evaluation and against a CPDI particle-step."};
  std::size_t points = 200000;
  int cells = 256, threads = 2;
  double end_time = 0.1;
  app.add_option("--points", points, "reference points per timing")->check(CLI::Range(1000, 100000000));
  app.add_option("--cells", cells, "cells of the ring run")->check(CLI::Range(8, 4096));
  app.add_option("--end-time", end_time, "simulated interval of the ring run [s]")->check(CLI::PositiveNumber);
  app.add_option("--threads", threads, "threads of the ring run")->check(CLI::Range(1, 256));
  CLI11_PARSE(app, argc, argv);

  mpmvv::set_threads(1);
  fmt::print("body force per evaluation, one thread, {} random points of each body\n", points);
  fmt::print("{:<34} {:>14} {:>14}\n", "solution", "ns/evaluation", "point by point");
  struct Variant {
    std::string label, problem;
    std::vector<std::string> overrides;
    bool closed_form = false;  // the scene's closed form (SceneSetup::fast_body_force)
  };
  const std::vector<Variant> variants = {
      {"ring (derived)", "ring", {"body_force=derived"}},
      {"ring, mooney-rivlin (derived)", "ring", {"body_force=derived", "material=mooney-rivlin"}},
      {"axis-aligned 2d (derived)", "axis-aligned", {"body_force=derived"}},
      {"axis-aligned 1d (derived)", "axis-aligned", {"body_force=derived", "variant=1d"}},
      {"expanding-ring (derived)", "expanding-ring", {"body_force=derived"}},
      {"rz-cylinder (derived)", "rz-cylinder", {"body_force=derived"}},
      {"ring (closed form, eqs. 2.14-2.15)", "ring", {}, true},
      {"axis-aligned 2d (closed form)", "axis-aligned", {}, true},
      {"axis-aligned 1d (closed form)", "axis-aligned", {"variant=1d"}, true},
      {"expanding-ring (closed form)", "expanding-ring", {}, true},
      {"rz-cylinder (closed form)", "rz-cylinder", {}, true},
  };
  for (const Variant& v : variants) {
    const mpmvv::app::SceneType& scene = *mpmvv::app::find_scene_type(v.problem);
    mpmvv::app::Config config(scene.name, scene.keys());
    for (const std::string& o : v.overrides) config.set_from_text(o);
    const mpmvv::app::SceneSetup s = scene.setup(config);
    const std::vector<mpmvv::Vec2> X = body_points(s, points);
    if (v.closed_form) {
      fmt::print("{:<34} {:>14.1f}\n", v.label, nanoseconds_per_evaluation(s, X, s.fast_body_force));
    } else {
      fmt::print("{:<34} {:>14.1f} {:>14.1f}\n", v.label,
                 nanoseconds_per_evaluation(s, X, mpmvv::mms::derived_force_field(s.solution)),
                 nanoseconds_per_evaluation(s, X, nullptr));
    }
  }

  mpmvv::set_threads(threads);
  fmt::print("\nring, CPDI, {} cells, 2 particles per direction, A = 0.5, t = 0 to {} s, {} threads\n", cells, end_time,
             threads);
  fmt::print("{:<12} {:>10} {:>14} {:>20} {:>22} {:>14}\n", "force", "wall [s]", "forcing share",
             "solver ns/p-step", "forcing ns/p-step", "p-steps/s");
  for (const char* kind : {"closed-form", "derived"}) {
    mpmvv::app::Config config("ring", mpmvv::app::find_scene_type("ring")->keys());
    for (const std::string& o : {std::string("cells=") + std::to_string(cells), fmt::format("end_time={}", end_time),
                                 fmt::format("output_times={}", end_time), std::string("body_force=") + kind})
      config.set_from_text(o);
    auto scene = mpmvv::app::find_scene_type("ring")->build(config);
    const mpmvv::RunOutcome o = scene->run({});
    const double steps = double(o.particle_steps);
    fmt::print("{:<12} {:>10.3g} {:>13.1f}% {:>20.1f} {:>22.1f} {:>14.3e}\n", kind, o.wall_seconds,
               100.0 * o.forcing_seconds / o.wall_seconds, 1e9 * (o.wall_seconds - o.forcing_seconds) / steps,
               1e9 * o.forcing_seconds / steps, steps / o.wall_seconds);
  }
  return 0;
}
