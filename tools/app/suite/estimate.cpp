// Run-time estimates of a suite's cases (estimate.hpp).
#include "estimate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <ostream>

#include <fmt/format.h>
#include <fmt/ostream.h>

#include "progress.hpp"
#include "solver/io/hdf5.hpp"
#include "solver/parallel.hpp"
#include "tools/app/config.hpp"
#include "tools/app/scene/scene.hpp"

namespace mpmvv::app {

namespace fs = std::filesystem;
using namespace suite_file;

namespace {

Config case_config(const SuiteCase& c) {
  return load_scene_file(
      c.scene_file,
      [](const std::string& n) -> std::optional<std::vector<KeySpec>> {
        const SceneType* t = find_scene_type(n);
        if (!t) return std::nullopt;
        return t->keys();
      },
      c.overrides);
}

// A case as the estimate sees it: its work at rest, and the group of cases
// (study and method) one calibration serves.
struct Work {
  const SuiteCase* c = nullptr;
  std::optional<WorkEstimate> w;
  std::string group;
  std::string why_not;  // not estimated: why
  std::optional<CaseState> done;
};

// What a run of a group measured: the steps it took over its steps at rest,
// its particle-steps per second, and (implicit) its wall time per load step
// and its particles.
struct Calibration {
  double step_factor = 1.0;
  double particle_factor = 1.0;     // particles stepped over the particles seeded (split domains add some)
  double seconds_per_work = 0.0;    // wall time over the work at rest (particles seeded x steps at rest)
  double rate = 0.0;
  double seconds_per_step = 0.0;
  std::size_t particles = 0;
  std::string basis;
};

// The calibration a run gives: `steps` taken to `reached` of `end_time` in
// `wall` seconds, against `w` (its work at rest to the end).
Calibration calibrate(const WorkEstimate& w, long long steps, long long particle_steps, double reached,
                      double end_time, double wall, std::string basis) {
  Calibration k;
  const double share = end_time > 0.0 ? std::clamp(reached / end_time, 1e-9, 1.0) : 1.0;
  k.step_factor = w.steps > 0 && steps > 0 ? double(steps) / (double(w.steps) * share) : 1.0;
  k.particle_factor = steps > 0 && w.particles > 0 ? double(particle_steps) / (double(steps) * double(w.particles)) : 1.0;
  const double work = double(w.particles) * double(w.steps) * share;
  k.seconds_per_work = work > 0.0 ? wall / work : 0.0;
  k.rate = wall > 0.0 ? double(particle_steps) / wall : 0.0;
  k.seconds_per_step = steps > 0 ? wall / double(steps) : 0.0;
  k.particles = w.particles;
  k.basis = std::move(basis);
  return k;
}

// The group's calibration from its finished cases in the directory (the one
// of most particle-steps, on as many threads), if any.
std::optional<Calibration> from_earlier_runs(const std::vector<Work>& works, const std::string& group,
                                             const SuiteDirectory& dir, int threads) {
  std::optional<Calibration> best;
  long long most = -1;
  for (const Work& k : works) {
    if (k.group != group || !k.done || !k.w) continue;
    try {
      const h5::File f = h5::File::open_read(dir.results(*k.c).string());
      const h5::Group root = f.root();
      if (root.attribute_int("threads") != threads) continue;
      const long long particle_steps = root.attribute_int("particle_steps");
      if (particle_steps <= most) continue;
      most = particle_steps;
      best = calibrate(*k.w, root.attribute_int("steps"), particle_steps, root.attribute_double("time_reached"),
                       root.attribute_double("end_time"), root.attribute_double("solver_time_s"),
                       fmt::format("the earlier run of {}", k.c->id));
    } catch (const std::exception&) {
      // a file without these attributes tells nothing
    }
  }
  return best;
}

// The group's cheapest case run now for at most kProbeSeconds of wall time.
std::optional<Calibration> probe(const Work& k, int threads, std::ostream& err) {
  fmt::print(err, "mpmvv suite: estimating: running {} for at most {:g} s\n", k.c->id, kProbeSeconds);
  const int before = max_threads();
  set_threads(threads);
  std::optional<Calibration> result;
  try {
    Config config = case_config(*k.c);
    auto scene = find_scene_type(config.scene())->build(config);
    const auto start = std::chrono::steady_clock::now();
    const RunOutcome o = scene->run([&](const mpmvv::Progress&) {
      if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > kProbeSeconds)
        stop_request().store(true, std::memory_order_relaxed);
    });
    stop_request().store(false, std::memory_order_relaxed);
    const double end_time = config.real("end_time");
    const double reached = o.completed ? end_time : o.time_reached;
    if (o.steps > 0 && reached > 0.0)
      result = calibrate(*k.w, o.steps, o.particle_steps, reached, end_time, o.wall_seconds,
                         o.completed ? fmt::format("{} run now", k.c->id)
                                     : fmt::format("{} run now to t = {:.3g} of {:g} s (a step that shrinks later "
                                                   "makes the case longer)",
                                                   k.c->id, reached, end_time));
  } catch (const std::exception&) {
    stop_request().store(false, std::memory_order_relaxed);
  }
  set_threads(before);
  return result;
}

}  // namespace

RunOutcome ring_rate_run(const std::vector<std::string>& settings, std::size_t* particles) {
  Config config("ring", find_scene_type("ring")->keys());
  // Centre seeding: the exact seeding's slivers at the rims (particles of
  // 3e-4 of a full one) stop linear MPM and exact CPDI at t = 0.034 s on 256
  // cells, and a rate measured over a run that stops is not the rate of the
  // method (a setting seeding=exact measures them all the same).
  config.set_from_text("seeding=centre");
  for (const std::string& s : settings) config.set_from_text(s);
  config.set_from_text(fmt::format("output_times={}", config.real("end_time")));
  auto scene = find_scene_type("ring")->build(config);
  const RunOutcome o = scene->run({});
  if (particles) *particles = scene->particle_count();
  return o;
}

std::vector<PlannedCase> plan_cases(const Suite& suite, const std::function<bool(const SuiteCase&)>& selected,
                                    const SuiteDirectory& dir, int jobs, int threads, std::ostream& err) {
  std::vector<Work> works;
  for (const SuiteCase& c : suite.cases) {
    if (!selected(c)) continue;
    Work k;
    k.c = &c;
    k.done = finished_state(dir.results(c), c);
    try {
      const Config config = case_config(c);
      const auto scene = find_scene_type(config.scene())->build(config);
      if (scene->external()) {
        k.why_not = "another program's run";
      } else {
        k.w = scene->estimate();
        if (!k.w) k.why_not = "the scene does not say its work";
      }
      k.group = c.study + " " + (config.has("method") ? config.text("method") : std::string()) + " " +
                (config.has("solver") ? config.text("solver") : std::string());
    } catch (const std::exception& ex) {
      k.why_not = ex.what();
    }
    works.push_back(std::move(k));
  }
  // One calibration a group: its earlier runs, else its cheapest case run now.
  std::map<std::string, std::optional<Calibration>> calibrations;
  for (const Work& k : works) {
    if (!k.w || k.done || calibrations.count(k.group)) continue;
    std::optional<Calibration> cal = from_earlier_runs(works, k.group, dir, threads);
    if (!cal) {
      const Work* cheapest = nullptr;
      for (const Work& o : works)
        if (o.group == k.group && o.w &&
            (!cheapest || o.w->particles * o.w->steps < cheapest->w->particles * cheapest->w->steps))
          cheapest = &o;
      cal = probe(*cheapest, threads, err);
    }
    calibrations[k.group] = cal;
  }
  std::vector<double> slots(std::size_t(std::max(1, jobs)), 0.0);
  std::vector<PlannedCase> plan;
  for (const Work& k : works) {
    PlannedCase p{k.c};
    CaseEstimate& e = p.estimate;
    if (k.w) e.particles = k.w->particles;
    if (k.done) {
      // It will not run again: nothing left of it.
      e.seconds = 0.0;
      e.basis = fmt::format("done: {} in {}", k.done->status, duration(k.done->wall));
    } else if (!k.w) {
      e.basis = "not estimated: " + k.why_not;
    } else if (const auto& cal = calibrations[k.group]; !cal || (!k.w->implicit && cal->rate <= 0.0)) {
      e.basis = "not estimated: its calibration run took no step";
    } else if (k.w->implicit) {
      // A Newton-Krylov solve's cost grows faster than its unknowns.
      e.steps = k.w->steps;
      e.seconds = cal->seconds_per_step * double(k.w->steps) *
                  std::pow(double(k.w->particles) / double(std::max<std::size_t>(1, cal->particles)), 1.5);
      e.basis = fmt::format("{:.3g} s a load step at {} particles ({})", cal->seconds_per_step, cal->particles,
                            cal->basis);
    } else {
      // The calibration's wall time per unit of work at rest: its steps'
      // growth, its particles' (split domains) and its rate in one.
      e.steps = (long long)std::llround(double(k.w->steps) * cal->step_factor);
      e.seconds = double(k.w->particles) * double(k.w->steps) * cal->seconds_per_work;
      e.basis = fmt::format("{:.2f} x the steps at rest, {:.2f} x the particles seeded, {:.3g} M particle-steps/s ({})",
                            cal->step_factor, cal->particle_factor, cal->rate * 1e-6, cal->basis);
    }
    double& slot = *std::min_element(slots.begin(), slots.end());
    p.start = slot;
    slot += e.seconds.value_or(0.0);
    p.end = slot;
    plan.push_back(std::move(p));
  }
  return plan;
}

}  // namespace mpmvv::app
