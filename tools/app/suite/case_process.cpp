#include "case_process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

extern char** environ;

namespace mpmvv::app::suite_file {

namespace fs = std::filesystem;

namespace {

// The last non-empty line of a log: the one-line message of a refused run.
std::string last_line(const fs::path& log) {
  std::istringstream in(read_text(log));
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

}  // namespace

pid_t spawn_case(const std::string& exe, const SuiteCase& c, const fs::path& results, const fs::path& log, int threads,
                 bool passive_wait, double checkpoint_seconds) {
  std::vector<std::string> args = {exe, "run", c.scene_file};
  for (const std::string& o : c.overrides) {
    args.push_back("--set");
    args.push_back(o);
  }
  for (const std::string& a : {std::string("-o"), results.string(), std::string("--quiet"), std::string("--threads"),
                               std::to_string(threads)})
    args.push_back(a);
  // A case the suite stopped goes on from its saved state.
  if (checkpoint_seconds > 0.0)
    for (const std::string& a : {std::string("--checkpoint-every"), fmt::format("{}", checkpoint_seconds),
                                 std::string("--resume-if-same")})
      args.push_back(a);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  std::vector<std::string> env_strings;
  for (char** e = environ; *e; ++e) {
    const std::string entry(*e);
    if (!(passive_wait && entry.rfind("OMP_WAIT_POLICY=", 0) == 0) && entry.rfind(std::string(kSuiteParent) + "=", 0) != 0)
      env_strings.push_back(entry);
  }
  // Cases share the cores: waiting threads must not spin on them. A case
  // alone keeps the suite's own policy (passive unless the user named one:
  // tools/cli/main.cpp).
  if (passive_wait) env_strings.emplace_back("OMP_WAIT_POLICY=passive");
  // The case ends with the suite, however the suite ends (run_case.cpp).
  env_strings.push_back(fmt::format("{}={}", kSuiteParent, ::getpid()));
  std::vector<char*> envp;
  for (std::string& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawnattr_t attributes;
  if (posix_spawn_file_actions_init(&actions) != 0 || posix_spawnattr_init(&attributes) != 0)
    throw std::runtime_error("posix_spawn initialisation failed");
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attributes, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, exe.c_str(), &actions, &attributes, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  if (rc != 0) throw std::runtime_error(fmt::format("posix_spawn {} failed: {}", exe, std::strerror(rc)));
  return pid;
}

CaseState ended_state(const SuiteDirectory& dir, const SuiteCase& c, int status, bool timed_out, double wall,
                      double timeout_seconds) {
  CaseState s;
  s.wall = wall;
  if (timed_out) {
    s.status = "timeout";
    s.detail = fmt::format("killed after {:.0f} s", timeout_seconds);
  } else if (WIFSIGNALED(status)) {
    s.status = "crashed";
    s.detail = fmt::format("signal {} ({})", WTERMSIG(status), strsignal(WTERMSIG(status)));
  } else {
    s.exit_code = WEXITSTATUS(status);
    if (s.exit_code == 0 || s.exit_code == 1) {
      if (const auto done = finished_state(dir.results(c), c)) {
        s = *done;
        s.wall = wall;
      } else {
        s.status = "error";
        s.detail = "the run ended without a usable results file (none, one without /errors, or one made with another MPMVV_FAULT)";
      }
    } else {
      s.status = "error";
      s.detail = last_line(dir.log(c));
    }
  }
  return s;
}

}  // namespace mpmvv::app::suite_file
