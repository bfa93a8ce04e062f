// Throughput of the explicit step on the ring scene: particle-steps per second
// for each shape-function family and thread count, best of several repeats.
// The run is the real scene (body force, tracers, output) from t = 0 over a
// short interval, so the number is what `mpmvv run` delivers (centre
// seeding: estimate.hpp, ring_rate_run, says why).
//
//   mpmvv-bench-throughput [--cells 256] [--end-time 0.1] [--repeats 3] [--threads 1,2] [--set KEY=VALUE]
//
// Beside the rate, each stage's wall time per particle-step (stage_times.hpp)
// and the bytes the particles, the stepper and its body force hold per particle.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "solver/parallel.hpp"
#include "solver/shape/cpdi_lanes.hpp"
#include "tools/app/suite/estimate.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Particle-steps per second of the explicit MPM step on the ring scene."};
  int cells = 256;
  double end_time = 0.1;
  int repeats = 3;
  std::vector<int> threads{1, 2};
  std::vector<std::string> methods{"linear", "gimp", "cpdi", "cpdi-exact"};
  std::string scheme = "usl";
  app.add_option("--cells", cells, "cells across the 3 m domain")->check(CLI::Range(8, 4096));
  app.add_option("--end-time", end_time, "simulated interval per repeat [s]")->check(CLI::PositiveNumber);
  app.add_option("--repeats", repeats, "repeats per configuration; the best is reported")->check(CLI::Range(1, 100));
  app.add_option("--threads", threads, "thread counts")->delimiter(',');
  app.add_option("--methods", methods, "shape-function families")->delimiter(',');
  app.add_option("--scheme", scheme, "usl, usf or musl");
  std::vector<std::string> extra;
  app.add_option("--set", extra, "further scene keys, KEY=VALUE (e.g. amplitude=1, seeding=centre)");
  CLI11_PARSE(app, argc, argv);

  fmt::print("ring scene (its defaults: A = 0.5, 2 particles per cell per direction; centre seeding), {} cells, {} to t = {} s{}, best of "
             "{}\n",
             cells, scheme, end_time, extra.empty() ? "" : ", " + fmt::format("{}", fmt::join(extra, ", ")), repeats);
  fmt::print("ns: wall time per particle-step, then the same for each stage (stage_times.hpp; other: set-up, the "
             "time loop, output, ledgers);\nbytes: what the particles, the stepper and its body force hold per "
             "particle; CPDI, uGIMP and linear stencils by the {} build of the lane kernels (solver/lanes.hpp; "
             "MPMVV_LANE_BUILD names another)\n",
             mpmvv::name(mpmvv::lane_build()));
  fmt::print("{:>10} {:>7} {:>9} {:>6} {:>16} {:>7} | {:>6} {:>6} {:>6} {:>6} {:>6} {:>7} {:>6} | {:>5}\n", "method",
             "threads", "particles", "steps", "particle-steps/s", "ns", "map", "grid", "update", "stress", "scan",
             "forcing", "other", "bytes");
  for (const std::string& method : methods) {
    for (int t : threads) {
      mpmvv::set_threads(t);
      double best_rate = 0.0;
      mpmvv::RunOutcome best;
      long long steps = 0;
      std::size_t particles = 0;
      std::string stopped;
      for (int r = 0; r < repeats; ++r) {
        std::vector<std::string> settings{"method=" + method, "scheme=" + scheme, "cells=" + std::to_string(cells),
                                          fmt::format("end_time={}", end_time)};
        settings.insert(settings.end(), extra.begin(), extra.end());
        const mpmvv::RunOutcome o = mpmvv::app::ring_rate_run(settings, &particles);
        // A run the solver stops still measures the steps it took; the row says so.
        if (!o.completed) stopped = fmt::format("  (stopped at t = {:.3g} s: {})", o.failure_time, o.failure_reason);
        const double rate = double(o.particle_steps) / o.wall_seconds;
        if (rate > best_rate) {
          best_rate = rate;
          best = o;
        }
        steps = o.steps;
      }
      // Each stage's wall time per particle-step; "other" is the rest of the
      // run's wall time (the time loop, output, work ledgers, domains turned or split).
      const mpmvv::StageTimes& st = best.stage_seconds;
      const double per = best.particle_steps > 0 ? 1e9 / double(best.particle_steps) : 0.0;
      const double other = best.wall_seconds - st.map - st.grid - st.update - st.stress - st.scan - best.forcing_seconds;
      fmt::print("{:>10} {:>7} {:>9} {:>6} {:>16.3e} {:>7.1f} | {:>6.1f} {:>6.1f} {:>6.1f} {:>6.1f} {:>6.1f} {:>7.1f} {:>6.1f} | "
                 "{:>5.0f}{}\n",
                 method, t, particles, steps, best_rate, 1e9 / best_rate, per * st.map, per * st.grid, per * st.update,
                 per * st.stress, per * st.scan, per * best.forcing_seconds, per * other, best.bytes_per_particle,
                 stopped);
    }
  }
  return 0;
}
