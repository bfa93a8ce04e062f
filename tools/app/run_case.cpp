#include "run_case.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <chrono>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <stdexcept>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>
#include <utility>

#include <fmt/format.h>
#include <fmt/ostream.h>

#include "config.hpp"
#include "mpmvv_commit.hpp"
#include "fault.hpp"
#include "installation.hpp"
#include "scene/scene.hpp"
#include "scene/results_file.hpp"
#include "scene/xdmf_file.hpp"
#include "solver/parallel.hpp"
#include "solver/time_loop.hpp"
#include "suite/suite.hpp"

namespace mpmvv::app {

namespace fs = std::filesystem;

std::string version_string() {
  return fmt::format("mpmvv {} (commit {}; built with: {})", MPMVV_VERSION, MPMVV_GIT_COMMIT, MPMVV_FEATURES);
}

int run_report_tool(const std::string& module, const std::vector<std::string>& arguments, std::ostream& err) {
  const std::string python = "/usr/bin/python3";
  const fs::path package = installation().reports;  // a folder named reports
  const fs::path path = package / (module + ".py");
  if (!fs::exists(python)) {
    fmt::print(err, "mpmvv: {} is missing: run tools/install-deps (Debian's python3 with numpy, h5py, matplotlib)\n", python);
    return 2;
  }
  if (!fs::exists(path) || !fs::exists(package / "__init__.py")) {
    fmt::print(err, "mpmvv: the report tools are missing ({} not found)\n", path.string());
    return 2;
  }
  // The package is imported from the directory that holds it, ahead of any
  // PYTHONPATH the caller set; -P keeps the working directory off the path,
  // where a folder of the same name would shadow it.
  const char* earlier = std::getenv("PYTHONPATH");
  const std::string search = package.parent_path().string() + (earlier && *earlier ? std::string(":") + earlier : "");
  if (::setenv("PYTHONPATH", search.c_str(), 1) != 0) {
    fmt::print(err, "mpmvv: cannot set PYTHONPATH: {}\n", std::strerror(errno));
    return 2;
  }
  std::vector<std::string> args = {python, "-P", "-m", package.filename().string() + "." + module};
  args.insert(args.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  err.flush();
  execv(python.c_str(), argv.data());
  fmt::print(err, "mpmvv: cannot start {}: {}\n", python, std::strerror(errno));
  return 2;
}

namespace {

Config load(const std::string& scene_file, const std::vector<std::string>& overrides) {
  return load_scene_file(
      scene_file,
      [](const std::string& name) -> std::optional<std::vector<KeySpec>> {
        const SceneType* t = find_scene_type(name);
        if (!t) return std::nullopt;
        return t->keys();
      },
      overrides);
}

std::string compact(const Config& c) {
  std::string s;
  for (const KeySpec& k : c.specs()) s += fmt::format(" {}={}", k.name, format_value(c.value(k.name)));
  return s;
}

// The first line where two texts differ, for a message.
std::string first_difference(const std::string& a, const std::string& b) {
  std::istringstream x(a), y(b);
  std::string p, q;
  while (true) {
    const bool more_x = bool(std::getline(x, p)), more_y = bool(std::getline(y, q));
    if (!more_x && !more_y) return "";
    if (!more_x) p = "(nothing)";
    if (!more_y) q = "(nothing)";
    if (p != q || !more_x || !more_y) return fmt::format("'{}' there, '{}' here", p, q);
  }
}

// The restart file the request asks for, and whether the run goes on from
// it: only from the state of the same run (configuration, build, threads,
// fault), since no other would continue with the same bits.
RestartPlan restart_plan(const RunRequest& request, const std::string& output, const Config& config, Fault fault,
                         std::ostream& err) {
  RestartPlan plan;
  using Resume = RunRequest::Resume;
  if (!(request.checkpoint_every > 0.0 || request.pause_at >= 0.0 || request.resume != Resume::no)) return plan;
  plan.path = restart_path(output);
  plan.every_seconds = request.checkpoint_every;
  if (request.pause_at >= 0.0) plan.pause_at = request.pause_at;
  plan.identity = {{"configuration", config.to_toml()},
                   {"version", version_string()},
                   {"threads", std::to_string(max_threads())},
                   {"fault", to_string(fault)}};
  // Each save is told, even with --quiet (a suite's case log shows them); on a
  // terminal the message ends the progress line first.
  const bool tty = isatty(fileno(stderr));
  plan.tell = [&err, tty](const std::string& message, bool failed) {
    fmt::print(err, "{}mpmvv run: {}{}\n", tty ? "\n" : "", failed ? "warning: " : "", message);
  };
  std::error_code ec;
  if (request.resume == Resume::no || !fs::exists(plan.path, ec)) return plan;
  std::string why_not;  // why the file's state is not this run's
  try {
    const h5::File file = h5::File::open_read(plan.path);
    const h5::Group root = file.root();
    for (const auto& [name, value] : plan.identity)
      if (const std::string saved = root.attribute_string(name); saved != value && why_not.empty())
        why_not = fmt::format("it holds the state of a run with another {} ({}), which would not go on with the "
                              "same bits", name, first_difference(saved, value));
    if (why_not.empty()) {
      const double saved_at = root.attribute_double("time");
      fmt::print(err, "mpmvv run: going on from {} (t = {:.6g} s, step {})\n", plan.path, saved_at,
                 root.attribute_int("steps"));
      if (request.pause_at >= 0.0 && saved_at >= request.pause_at)
        fmt::print(err, "mpmvv run: --pause-at {:.6g}: the saved state is at t = {:.6g} s already, so the run stops "
                   "again before its first step (drop --pause-at or give a later time to go on)\n",
                   request.pause_at, saved_at);
    }
  } catch (const std::exception& e) {
    why_not = fmt::format("it cannot be read ({})", e.what());
  }
  if (why_not.empty()) {
    plan.resume = true;
  } else if (request.resume == Resume::yes) {
    throw ConfigError(fmt::format("the restart file {}: {}; remove it to start again", plan.path, why_not));
  } else {
    fmt::print(err, "mpmvv run: starting from t = 0: the restart file {}: {}\n", plan.path, why_not);
  }
  return plan;
}

// On a terminal one line rewritten every second; in a log a new line every
// ten seconds.
ProgressSink progress_printer(std::ostream& err) {
  const bool tty = isatty(fileno(stderr));
  auto last_line = std::make_shared<std::chrono::steady_clock::time_point>(std::chrono::steady_clock::now());
  return [&err, tty, last_line](const Progress& p) {
    const std::string line =
        fmt::format("step {:>7}  t = {:.4g} / {:.4g} s  {:.3g} particle-steps/s  ETA {:.0f} s", p.step, p.time,
                    p.end_time, p.particle_steps_per_second, p.eta_seconds);
    if (tty) {
      fmt::print(err, "\r{:<78}", p.final ? fmt::format("step {:>7}  t = {:.4g} s  done", p.step, p.time) : line);
      if (p.final) fmt::print(err, "\n");
    } else if (!p.final && std::chrono::steady_clock::now() - *last_line >= std::chrono::seconds(10)) {
      *last_line = std::chrono::steady_clock::now();
      fmt::print(err, "{}\n", line);
    }
    err.flush();
  };
}

}  // namespace

std::string restart_path(const std::string& output) { return output + ".restart"; }

namespace {

// An exclusive lock on a results file's FILE.lock for one run (lock_results),
// released and removed when the run ends.
class ResultsLock {
 public:
  ResultsLock() = default;
  ResultsLock(ResultsLock&& o) noexcept : fd_(std::exchange(o.fd_, -1)), path_(std::move(o.path_)) {}
  ResultsLock& operator=(ResultsLock&& o) noexcept {
    std::swap(fd_, o.fd_);
    std::swap(path_, o.path_);
    return *this;
  }
  ~ResultsLock();

 private:
  friend ResultsLock lock_results(const std::string& output);
  int fd_ = -1;
  std::string path_;
};

ResultsLock::~ResultsLock() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());
  ::close(fd_);
}

// What the run will write is known writable before it runs (a directory of
// that name, a name too long, a folder without write permission: each found
// at once, not after the simulation), and no other run writes it meanwhile:
// an exclusive flock on FILE.lock, held to the end (two runs on one results
// file would each exit 0 and the last rename would win).
ResultsLock lock_results(const std::string& output) {
  std::error_code ec;
  if (fs::is_directory(output, ec))
    throw ConfigError(fmt::format("-o {}: is a directory; name the results file (.h5) to write", output));
  ResultsLock lock;
  lock.path_ = output + ".lock";
  lock.fd_ = ::open(lock.path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock.fd_ < 0)
    throw ConfigError(fmt::format("-o {}: cannot write there: {}", output, std::strerror(errno)));
  if (::flock(lock.fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(lock.fd_);
    lock.fd_ = -1;
    throw ConfigError(fmt::format("-o {}: another mpmvv run is writing this results file now ({} is locked)", output,
                                  lock.path_));
  }
  // The file the results are written to first (then renamed): made and
  // removed here, or, left by an earlier run, opened for writing and left.
  const std::string partial = output + ".partial";
  int probe = ::open(partial.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  const bool made = probe >= 0;
  if (!made && errno == EEXIST) probe = ::open(partial.c_str(), O_WRONLY | O_CLOEXEC);
  if (probe < 0) throw ConfigError(fmt::format("-o {}: cannot write {}: {}", output, partial, std::strerror(errno)));
  ::close(probe);
  if (made) ::unlink(partial.c_str());
  return lock;
}

}  // namespace

std::string describe_configuration(const std::string& scene_file, const std::vector<std::string>& overrides) {
  const Config c = load(scene_file, overrides);
  std::string s = fmt::format("scene = \"{}\"  # {}\n", c.scene(), find_scene_type(c.scene())->summary);
  for (const KeySpec& k : c.specs())
    s += fmt::format("{} = {}\n    # {}; {} (from {})\n", k.name, format_value(c.value(k.name)), k.help,
                     k.describe_range(), c.origin(k.name).source);
  return s;
}

std::string describe_scenes() {
  std::string s;
  for (const SceneType& t : scene_types()) {
    s += fmt::format("{}: {}\n", t.name, t.summary);
    for (const KeySpec& k : t.keys())
      s += fmt::format("  {:<24} default {:<12} {}; {}\n", k.name, format_value(k.default_value), k.help,
                       k.describe_range());
  }
  return s;
}

int run_case(const RunRequest& request, std::ostream& out, std::ostream& err) {
  // A case a suite started ends with that suite: SIGTERM when the suite's
  // process ends (it then writes what it computed, marked interrupted, which
  // a rerun runs again); a suite already gone is not waited for.
  if (const char* parent = std::getenv(kSuiteParent); parent && *parent) {
    if (::prctl(PR_SET_PDEATHSIG, SIGTERM) != 0 || std::to_string(::getppid()) != parent) {
      fmt::print(err, "mpmvv run: the suite that started this case (process {}) has ended\n", parent);
      return 2;
    }
    // Not for the programs this run starts (an external_command may be mpmvv itself).
    ::unsetenv(kSuiteParent);
  }
  std::unique_ptr<SceneCase> scene;
  Config config("", {});
  std::string output = request.output;
  ResultsLock results_lock;
  Fault fault;
  try {
    config = load(request.scene_file, request.overrides);
    scene = find_scene_type(config.scene())->build(config);
    if (output.empty()) output = fs::path(request.scene_file).stem().string() + ".h5";
    fault = injected_fault(output);
    scene->inject(fault);
    scene->set_results_path(output);
    if (fs::path(output).extension() != ".h5")
      throw ConfigError(fmt::format("-o {}: the results file must end in .h5", output));
    const fs::path parent = fs::absolute(output).parent_path();
    std::error_code ec;
    fs::create_directories(parent, ec);
    if (ec) throw ConfigError(fmt::format("-o {}: cannot create directory {}: {}", output, parent.string(), ec.message()));
    results_lock = lock_results(output);
  } catch (const ConfigError& e) {
    fmt::print(err, "mpmvv run: {}\n", e.what());
    return 2;
  }
  set_threads(request.threads);
  if (fault == Fault::crash) std::abort();
  while (fault == Fault::hang) std::this_thread::sleep_for(std::chrono::seconds(1));
  RestartPlan restart;
  try {
    restart = restart_plan(request, output, config, fault, err);
  } catch (const ConfigError& e) {
    fmt::print(err, "mpmvv run: {}\n", e.what());
    return 2;
  }

  if (!request.quiet)
    fmt::print(err, "mpmvv run {} -> {} ({} threads)\nconfiguration:{}\n", request.scene_file, output, max_threads(),
               compact(config));
  // SIGINT, SIGTERM and SIGHUP (a closed terminal) end the run at its next
  // step, and what it computed is written, marked "interrupted" (a second
  // signal kills as usual).
  struct sigaction action {};
  action.sa_handler = [](int) { stop_request().store(true, std::memory_order_relaxed); };
  action.sa_flags = SA_RESETHAND;
  sigemptyset(&action.sa_mask);
  static constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP};
  struct Restore {
    struct sigaction before[3] = {};
    ~Restore() {
      for (int i = 0; i < 3; ++i) sigaction(kStopSignals[i], &before[i], nullptr);
    }
  } restore;
  for (int i = 0; i < 3; ++i) sigaction(kStopSignals[i], &action, &restore.before[i]);
  RunOutcome o;
  try {
    o = scene->run(request.quiet ? ProgressSink{} : progress_printer(err), restart);
  } catch (const ConfigError& e) {
    fmt::print(err, "mpmvv run: {}\n", e.what());
    return 2;
  } catch (const std::invalid_argument& e) {
    // The solver refuses a model it cannot step (make_stepper's checks).
    fmt::print(err, "mpmvv run: {}: the solver refuses the seeded model: {}\n", request.scene_file, e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    // What the estimate before the run let through (refuse_what_cannot_fit).
    fmt::print(err, "mpmvv run: {}: out of memory ({} threads): use fewer cells, particles per direction or "
               "threads\n", request.scene_file, max_threads());
    return 2;
  }

  // Write next to the target and rename: a killed run never leaves a file that
  // looks whole.
  const RunHealth health = scene->health();
  const std::string partial = output + ".partial";
  try {
    write_results_file(partial, {request.scene_file, request.overrides, request.command_line, version_string()}, config,
                       *scene, o, health, fault);
    fs::rename(partial, output);
  } catch (const std::exception& e) {
    std::error_code ec;
    fs::remove(partial, ec);
    fmt::print(err, "mpmvv run: writing {} failed: {}\n", output, e.what());
    return 2;
  }
  // The ParaView sidecar, from the file as written; the results stand without
  // it (an external program's run that wrote no output has no particles to show).
  if (scene->particle_count() > 0) {
    try {
      write_xdmf_sidecar(output);
    } catch (const std::exception& e) {
      fmt::print(err, "mpmvv run: {} is written; its ParaView sidecar {} is not: {}\n", output,
                 xdmf_sidecar_path(output), e.what());
    }
  }


  const double rate = o.wall_seconds > 0 ? double(o.particle_steps) / o.wall_seconds : 0.0;
  const std::string place =
      health.reference_position
          ? fmt::format(", at the particle from ({:.4g}, {:.4g})", health.reference_position->x(),
                        health.reference_position->y())
          : std::string();
  // Who ran it: mpmvv's method, or the external program.
  const std::string method = scene->external() ? std::string("(external program)") : config.text("method");
  if (o.completed && health.lost)
    fmt::print(out, "{} {}: SOLUTION LOST (status \"lost\"): it ran to t = {:.4g} s in {} steps, but at t = {:.4g} s {}{}\n",
               config.scene(), method, o.time_reached, o.steps, health.time, health.reason, place);
  else if (o.completed && scene->external())
    fmt::print(out, "{} {}: completed t = {:.4g} s, {:.3g} s wall, {} particles at the end, h = {:.4g} m\n",
               config.scene(), method, o.time_reached, o.wall_seconds, scene->particle_count(), scene->cell_size());
  else if (o.completed)
    fmt::print(out, "{} {}: completed t = {:.4g} s in {} steps, {:.3g} s wall ({:.3g} s forcing), {} particles, h = {:.4g} m, {:.3g} particle-steps/s\n",
               config.scene(), config.text("method"), o.time_reached, o.steps, o.wall_seconds, o.forcing_seconds,
               scene->particle_count(), scene->cell_size(), rate);
  else if (o.failure_reason == kInterrupted)
    fmt::print(out, "{} {}: INTERRUPTED at t = {:.4g} s, step {}: what it computed is written (status \"interrupted\")\n",
               config.scene(), method, o.failure_time, o.failure_step);
  else
    fmt::print(out, "{} {}: FAILED at t = {:.4g} s{}{}: {} ({})\n", config.scene(), method, o.failure_time,
               scene->external() ? std::string() : fmt::format(", step {}", o.failure_step),
               o.failure_particle >= 0 ? fmt::format(", particle {}", o.failure_particle) : std::string(),
               o.failure_reason, o.failure_detail);
  if (!o.completed && health.lost && o.failure_reason != kInterrupted)
    fmt::print(out, "its solution was lost before: at t = {:.4g} s {}{}\n", health.time, health.reason, place);
  print_error_table(out, scene->errors());
  print_measurements(out, scene->measurements());
  fmt::print(out, "results: {}\n", output);
  // The state of a run that has ended is of no more use: its results are whole.
  if (!restart.path.empty()) {
    std::error_code ec;
    if (o.failure_reason != kInterrupted)
      fs::remove(restart.path, ec);
    else if (fs::exists(restart.path, ec))
      fmt::print(out, "its state: {} (go on with the same command and --resume)\n", restart.path);
  }
  if (o.failure_reason == kInterrupted) return 130;
  return o.completed && !health.lost ? 0 : 1;
}

}  // namespace mpmvv::app
