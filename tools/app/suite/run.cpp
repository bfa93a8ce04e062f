// Running a suite: every case in a process of its own (`mpmvv run`), a few at
// once, each killed past the suite's time-out; what a case leaves is recorded
// as it ends, so an interrupted suite resumes where it stopped. Under mpirun
// the ranks share out the cases.
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <regex>
#include <thread>

#include <fmt/format.h>
#include <fmt/ostream.h>
#include <fmt/ranges.h>

#include "case_process.hpp"
#include "estimate.hpp"
#include "manifest.hpp"
#include "progress.hpp"
#include "ranks.hpp"
#include "suite.hpp"
#include "tools/app/config.hpp"

namespace mpmvv::app {

namespace fs = std::filesystem;
using namespace suite_file;
using Clock = std::chrono::steady_clock;

namespace {

volatile sig_atomic_t interrupted = 0;
void on_interrupt(int) { interrupted = 1; }

constexpr double kTimeoutGrace = 10.0;  // seconds a timed-out case has to end after SIGTERM

// The estimated total of a plan, and with a budget the cases it leaves out.
void print_plan_total(const Suite& suite, const std::vector<PlannedCase>& plan, int jobs, int threads, double budget,
                      std::ostream& out) {
  double total = 0.0, wall = 0.0;
  int unknown = 0, over = 0;
  std::vector<std::string> unreached;
  for (const PlannedCase& p : plan) {
    if (!p.estimate.seconds) {
      ++unknown;
      continue;
    }
    total += *p.estimate.seconds;
    wall = std::max(wall, p.end);
    over += *p.estimate.seconds > suite.timeout_seconds;
    if (budget > 0.0 && p.end > budget) unreached.push_back(p.c->id);
  }
  fmt::print(out, "estimated: {} of case time, about {} of wall time with {} case{} at once on {} thread{} each{}{}\n",
             duration(total), duration(wall), jobs, jobs > 1 ? "s" : "", threads, threads > 1 ? "s" : "",
             unknown ? fmt::format(", not counting {} case{} not estimated", unknown, unknown > 1 ? "s" : "") : "",
             over ? fmt::format("; {} case{} past the timeout", over, over > 1 ? "s" : "") : "");
  if (budget > 0.0)
    fmt::print(out, "{}\n",
               unreached.empty()
                   ? fmt::format("budget {}: every estimated case ends within it", duration(budget))
                   : fmt::format("budget {}: {} case{} would not end within it: {}", duration(budget), unreached.size(),
                                 unreached.size() > 1 ? "s" : "", fmt::join(unreached, ", ")));
}

// Each selected case with its settings and an estimate of its run time
// (estimate.hpp), then the suite's total and its wall time with `jobs` cases
// at once; with a budget, the cases a run of that wall time will not reach.
void list_cases(const Suite& suite, const std::vector<PlannedCase>& plan, int jobs, int threads, double budget,
                const SuiteDirectory& dir, std::ostream& out) {
  fmt::print(out, "suite {} ({} tier): {} cases, timeout {} s{}\n", suite.file, suite.tier, suite.cases.size(),
             suite.timeout_seconds, suite.description.empty() ? "" : "\n" + suite.description);
  fmt::print(out, "{:<48} {:>10} {:>8} {:>10}  {}\n", "case", "particles", "steps", "estimate", "settings; estimate from");
  for (const PlannedCase& p : plan) {
    const CaseEstimate& e = p.estimate;
    std::string settings;
    for (const std::string& o : p.c->overrides)
      settings += o.find(' ') == std::string::npos ? " --set " + o : " --set '" + o + "'";
    std::string notes;
    if (e.seconds && *e.seconds > suite.timeout_seconds) notes += " (over the suite's timeout)";
    if (budget > 0.0 && e.seconds && p.end > budget) notes += " (past the budget)";
    fmt::print(out, "{:<48} {:>10} {:>8} {:>10}  {}{}; {}{}\n", p.c->id,
               e.particles ? fmt::format("{}", *e.particles) : "-", e.steps ? fmt::format("{}", *e.steps) : "-",
               e.seconds ? duration(*e.seconds) : "-", p.c->scene_file, settings, e.basis, notes);
  }
  print_plan_total(suite, plan, jobs, threads, budget, out);
  fmt::print(out, "(each study and method calibrated on an earlier run in {} or on its cheapest case run now: "
                  "estimate.hpp)\n",
             dir.root.string());
}

// One suite at a time on a directory: a second would rename the first's
// partial files and rewrite its manifest. The lock (flock on DIR/.lock, held
// until this process exits, not by the cases it starts) is released by the
// kernel however the holder ends. A directory that holds another suite's
// manifest is refused unless asked (`force`). Returns why the directory is
// refused, or "" when it is this run's.
std::string claim_directory(const SuiteDirectory& dir, const Suite& suite, bool force) {
  const fs::path lock_file = dir.root / ".lock";
  const int fd = ::open(lock_file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) return fmt::format("-o {}: cannot open {}: {}", dir.root.string(), lock_file.string(), std::strerror(errno));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0)
    return fmt::format("-o {}: another mpmvv suite is running in this directory (it holds {}); wait for it, "
                       "or choose another directory",
                       dir.root.string(), lock_file.string());
  // The descriptor stays open, and the lock held, until this process exits.
  if (fs::exists(dir.manifest()) && !force) {
    const Json manifest = read_json(dir.manifest());
    const std::string other = member<std::string>(manifest, "suite", suite.name);
    if (other != suite.name)
      return fmt::format("-o {}: the directory holds the results of suite '{}' (its manifest.json); choose "
                         "another directory, or --force to run '{}' there and replace that manifest",
                         dir.root.string(), other, suite.name);
    // A manifest written before tiers existed is the full tier's.
    const std::string other_tier = member<std::string>(manifest, "tier", kFullTier);
    if (other_tier != suite.tier)
      return fmt::format("-o {}: the directory holds the {} tier of suite '{}'; choose another directory, or "
                         "--force to run the {} tier there and replace that manifest (cases of the same "
                         "configuration are kept)",
                         dir.root.string(), other_tier, suite.name, suite.tier);
  }
  return "";
}
// The table of every case's state, from the state files all ranks wrote;
// `status` becomes 1 when a selected case did not end as a result.
std::string summary_table(const SuiteDirectory& dir, const Suite& suite,
                          const std::function<bool(const SuiteCase&)>& selected, double seconds, int& status) {
  std::string table = fmt::format("suite {} ({} cases) -> {}\n{:<48} {:<10} {:>9}  {}\n", suite.name, suite.cases.size(),
                                  dir.root.string(), "case", "status", "wall [s]", "detail");
  std::map<std::string, int> counts;
  for (const SuiteCase& c : suite.cases) {
    const Json json = read_json(dir.state(c));
    const std::string case_status = member<std::string>(json, "status", "pending");
    const double wall = member<double>(json, "wall_time_s", 0.0);
    const std::string detail = member<std::string>(json, "detail", "");
    ++counts[case_status];
    const std::string error = fs::exists(dir.results(c)) ? headline_error(dir.results(c)) : "";
    table += fmt::format("{:<48} {:<10} {:>9.3g}  {}\n", c.id, case_status, wall,
                         detail.empty() ? error : detail + (error.empty() ? "" : "; " + error));
    // The exit status speaks of the cases this run ran: one --only left out
    // keeps whatever an earlier run left it (pending, or in error), as
    // suites/README.md says.
    if (selected(c) && case_status != "completed" && case_status != "failed" && case_status != "lost") status = 1;
  }
  std::string totals;
  for (const auto& [k, v] : counts) totals += fmt::format("{}{} {}", totals.empty() ? "" : ", ", v, k);
  return table + fmt::format("{} in {}\n", totals, duration(seconds));
}

// The cases of one rank as they run: which wait, which run, what each left.
class CaseQueue {
 public:
  CaseQueue(const Suite& suite, const SuiteDirectory& dir, std::ostream& err, bool quiet, std::string prefix)
      : suite_(suite), dir_(dir), err_(err), quiet_(quiet), prefix_(std::move(prefix)), state_(suite.cases.size()) {}

  // This rank's share, less what an earlier run already finished (recorded
  // as kept) and what --only leaves out.
  void share(int rank, int ranks, const std::function<bool(const SuiteCase&)>& selected) {
    for (std::size_t i = 0; i < suite_.cases.size(); ++i) {
      if (i % std::size_t(ranks) != std::size_t(rank)) continue;
      const SuiteCase& c = suite_.cases[i];
      if (const auto done = finished_state(dir_.results(c), c)) {
        state_[i] = *done;
        state_[i].detail = (state_[i].detail.empty() ? "" : state_[i].detail + "; ") + "kept from an earlier run";
        guarded([&] { record_case(dir_, c, state_[i]); });
        ++resumed_;
      } else if (selected(c)) {
        queue_.push_back(i);
      } else {
        ++unselected_;
      }
    }
  }

  std::size_t queued() const { return queue_.size(); }
  std::size_t resumed() const { return resumed_; }
  std::size_t unselected() const { return unselected_; }
  std::size_t finished() const { return finished_; }
  bool done() const { return next_ == queue_.size() && running_.empty(); }
  // A write of the suite's own files that failed (a full disk) stops the
  // suite as an interrupt does: what is finished stays, and the last
  // manifest written stays whole.
  const std::string& write_failure() const { return write_failure_; }
  bool stopping() const { return interrupted || !write_failure_.empty(); }

  // Starts cases until `jobs` run.
  void start(const std::string& exe, int jobs, int threads, bool passive) {
    std::error_code ec;
    while (next_ < queue_.size() && int(running_.size()) < jobs && !stopping()) {
      const std::size_t i = queue_[next_++];
      const SuiteCase& c = suite_.cases[i];
      fs::remove(dir_.results(c), ec);
      try {
        running_.push_back({i, spawn_case(exe, c, dir_.results(c), dir_.log(c), threads, passive, suite_.checkpoint_seconds),
                            Clock::now()});
        state_[i].status = "running";
      } catch (const std::exception& e) {
        state_[i] = {"error", -1, 0.0, e.what()};
        guarded([&] { record_case(dir_, c, state_[i]); });
        ++finished_;
      }
    }
  }

  // Records whatever ended and kills what overran its time; the manifest is
  // rewritten after each case when one rank runs them all.
  void reap(bool terminal, bool one_rank) {
    std::error_code ec;
    for (auto it = running_.begin(); it != running_.end();) {
      int status = 0;
      const pid_t r = waitpid(it->pid, &status, WNOHANG);
      const double wall = std::chrono::duration<double>(Clock::now() - it->start).count();
      if (r == 0) {
        // SIGTERM first: the case ends its external program's own process
        // group and writes what it computed; SIGKILL if it has not ended
        // kTimeoutGrace seconds later.
        if (wall > suite_.timeout_seconds && !it->timed_out) {
          kill(-it->pid, SIGTERM);
          it->timed_out = true;
        } else if (it->timed_out && wall > suite_.timeout_seconds + kTimeoutGrace) {
          kill(-it->pid, SIGKILL);
        }
        ++it;
        continue;
      }
      const SuiteCase& c = suite_.cases[it->index];
      CaseState& s = state_[it->index];
      s = ended_state(dir_, c, status, it->timed_out, wall, suite_.timeout_seconds);
      fs::remove(dir_.results(c).string() + ".partial", ec);
      guarded([&] { record_case(dir_, c, s); });
      ++finished_;
      finished_wall_ += wall;
      if (!terminal && !quiet_)
        fmt::print(err_, "{}case {}: {} ({:.3g} s){}\n", prefix_, c.id, s.status, wall, s.detail.empty() ? "" : ", " + s.detail);
      if (one_rank) guarded([&] { write_manifest(dir_, suite_); });
      it = running_.erase(it);
    }
  }

  // Stops every running case (SIGTERM to its process group: it writes what
  // it reached) and waits for it.
  void stop_all() {
    std::error_code ec;
    for (const Running& r : running_) kill(-r.pid, SIGTERM);
    for (const Running& r : running_) waitpid(r.pid, nullptr, 0);
    for (const Running& r : running_) fs::remove(dir_.results(suite_.cases[r.index]).string() + ".partial", ec);
  }

  void show(Progress& progress, bool force) const {
    progress.show(queue_, state_, finished_, finished_wall_, running_.size(), force);
  }

  template <class Write>
  void guarded(Write&& write) {
    if (!write_failure_.empty()) return;
    try {
      write();
    } catch (const std::exception& e) {
      write_failure_ = e.what();
    }
  }

 private:
  struct Running {
    std::size_t index;
    pid_t pid;
    Clock::time_point start;
    bool timed_out = false;
  };
  const Suite& suite_;
  const SuiteDirectory& dir_;
  std::ostream& err_;
  bool quiet_;
  std::string prefix_;
  std::vector<CaseState> state_;
  std::vector<std::size_t> queue_;
  std::vector<Running> running_;
  std::size_t next_ = 0, finished_ = 0, resumed_ = 0, unselected_ = 0;
  double finished_wall_ = 0.0;
  std::string write_failure_;
};

}  // namespace

int run_suite(const SuiteRequest& request, std::ostream& out, std::ostream& err) {
  const Ranks ranks;
  if (ranks.failed()) {
    fmt::print(err, "mpmvv suite: MPI_Init failed\n");
    return 2;
  }
  Suite suite;
  try {
    suite = load_suite(request.suite_file, request.tier);
  } catch (const SuiteSkipped& e) {
    // A suite that needs a program built elsewhere: nothing to run, not a fault.
    if (ranks.first()) fmt::print(err, "mpmvv suite: skipped: {}\n", e.what());
    return 0;
  } catch (const ConfigError& e) {
    if (ranks.first()) fmt::print(err, "mpmvv suite: {}\n", e.what());
    return 2;
  }
  if (ranks.first())
    for (const std::string& w : suite.warnings) fmt::print(err, "mpmvv suite: warning: {}\n", w);
  std::regex only;
  try {
    only = std::regex(request.only.empty() ? std::string(".") : request.only);
  } catch (const std::regex_error& e) {
    if (ranks.first()) fmt::print(err, "mpmvv suite: --only '{}': not a regular expression ({})\n", request.only, e.what());
    return 2;
  }
  // --only: the cases the request selects; the others stay as an earlier run left them.
  const std::function<bool(const SuiteCase&)> selected = [&](const SuiteCase& c) {
    return request.only.empty() || std::regex_search(c.id, only);
  };
  if (std::none_of(suite.cases.begin(), suite.cases.end(), selected)) {
    if (ranks.first())
      fmt::print(err, "mpmvv suite: --only '{}' matches no case of {} (its ids look like '{}'; --list shows them)\n",
                 request.only, suite.file, suite.cases.empty() ? std::string() : suite.cases.front().id);
    return 2;
  }
  const SuiteDirectory dir{!request.output_dir.empty() ? fs::path(request.output_dir)
                           : suite.tier == kFullTier ? fs::path("results") / suite.name
                                                     : fs::path("results") / (suite.name + "-" + suite.tier)};
  const int cores = std::max(1u, std::thread::hardware_concurrency());
  const int jobs = std::max(1, request.jobs);
  const int threads = request.threads > 0 ? request.threads : std::max(1, cores / (jobs * ranks.count()));
  if (request.list) {
    if (ranks.first()) list_cases(suite, plan_cases(suite, selected, dir, jobs, threads, err), jobs, threads,
                                  request.budget_seconds, dir, out);
    return 0;
  }
  if (request.budget_seconds > 0.0 && ranks.first())
    print_plan_total(suite, plan_cases(suite, selected, dir, jobs, threads, err), jobs, threads, request.budget_seconds,
                     err);
  std::error_code ec;
  fs::create_directories(dir.cases(), ec);
  if (ec) {
    if (ranks.first())
      fmt::print(err, "mpmvv suite: -o {}: cannot create {}: {}\n", dir.root.string(), dir.cases().string(), ec.message());
    return 2;
  }
  const std::string refusal = ranks.first() ? claim_directory(dir, suite, request.force) : "";
  int refused = !refusal.empty();
  ranks.share_first(refused);
  if (refused) {
    if (ranks.first()) fmt::print(err, "mpmvv suite: {}\n", refusal);
    return 2;
  }
  if (ranks.first()) {
    // Whole or not at all: a full disk must not leave a short suite.toml under its name.
    try {
      write_atomically(dir.root / "suite.toml", suite.text);
    } catch (const std::exception& e) {
      fmt::print(err, "mpmvv suite: -o {}: cannot write suite.toml: {}\n", dir.root.string(), e.what());
      refused = 1;
    }
  }
  ranks.share_first(refused);
  if (refused) return 2;

  const std::string prefix = ranks.count() > 1 ? fmt::format("[rank {}] ", ranks.rank()) : "";
  CaseQueue cases(suite, dir, err, request.quiet, prefix);
  cases.share(ranks.rank(), ranks.count(), selected);
  const bool passive = jobs * ranks.count() > 1 || request.threads > 0;  // threads set: others share the cores
  const std::string exe = self_executable();
  Progress progress(err, request.quiet, prefix, jobs);
  if (!request.quiet)
    fmt::print(err, "{}mpmvv suite {}: {} cases ({} here, {} kept from an earlier run{}), {} at once, {} threads each{} -> {}\n",
               prefix, suite.file, suite.cases.size(), cases.queued() + cases.resumed() + cases.unselected(),
               cases.resumed(),
               cases.unselected() ? fmt::format(", {} left pending by --only", cases.unselected()) : std::string(),
               jobs, threads,
               suite.checkpoint_seconds > 0.0
                   ? fmt::format(", each saving its state every {} (a rerun goes on from it)",
                                 duration(suite.checkpoint_seconds))
                   : std::string(),
               dir.root.string());

  struct sigaction action {};
  action.sa_handler = on_interrupt;
  // A closed terminal (SIGHUP) stops the suite as SIGTERM does, not silently.
  for (int signal : {SIGINT, SIGTERM, SIGHUP}) sigaction(signal, &action, nullptr);

  const auto suite_start = Clock::now();
  const bool one_rank = ranks.count() == 1;
  while (!cases.done() && !cases.stopping()) {
    cases.start(exe, jobs, threads, passive);
    cases.reap(progress.terminal(), one_rank);
    cases.show(progress, false);
    if (!cases.done()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const bool newline = progress.terminal() && !request.quiet;
  if (cases.stopping()) {
    cases.stop_all();
    if (one_rank) cases.guarded([&] { write_manifest(dir, suite); });
    if (newline) fmt::print(err, "\n");
    if (!cases.write_failure().empty()) {
      fmt::print(err, "{}mpmvv suite: {}; the suite stopped: {} {} finished, their results and the last manifest "
                 "written are kept; make room and rerun the same command to resume\n",
                 prefix, cases.write_failure(), cases.finished(), cases.finished() == 1 ? "case" : "cases");
      return 1;
    }
    fmt::print(err, "{}mpmvv suite: interrupted; {} cases finished; rerun the same command to resume\n", prefix,
               cases.finished());
    return 130;
  }
  cases.show(progress, true);
  if (newline) fmt::print(err, "\n");

  ranks.wait_for_all();
  int status = 0;
  if (ranks.first()) {
    cases.guarded([&] { write_manifest(dir, suite); });
    const std::string table = summary_table(dir, suite, selected,
                                            std::chrono::duration<double>(Clock::now() - suite_start).count(), status);
    cases.guarded([&] { write_atomically(dir.root / "summary.txt", table); });
    fmt::print(out, "{}", table);
    if (!cases.write_failure().empty()) {
      fmt::print(err, "mpmvv suite: {}; every case finished, and the results written are kept; make room and rerun "
                 "the same command to write the manifest and summary\n", cases.write_failure());
      status = 1;
    }
  }
  return status;
}


}  // namespace mpmvv::app
