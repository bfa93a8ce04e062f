#include "external_program.hpp"

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

#include "solver/time_loop.hpp"
#include "tools/app/installation.hpp"
#include "tools/app/json.hpp"

namespace mpmvv::app {

namespace fs = std::filesystem;

namespace {

constexpr const char* kVtkStressOrderText = "xx, yy, zz, xy, yz, xz";

// external_stress_order as parsed (VTK's own order however it is spelled),
// refused naming the key when malformed.
StressOrder stress_order_of(const Config& config) {
  try {
    return parse_stress_order(config.text("external_stress_order"));
  } catch (const std::invalid_argument& e) {
    config.reject("external_stress_order", e.what());
  }
}

}  // namespace

std::vector<KeySpec> external_program_keys() {
  const double inf = std::numeric_limits<double>::infinity();
  return {
      {"external_command", KeyKind::text, std::string(""),
       "another MPM code to run in place of mpmvv's solver (empty: mpmvv's own): a /bin/sh command line in which "
       "{KEY} is any key's value and {input}, {scene}, {output}, {log}, {mpmvv}, {threads}, {suites} are the case's "
       "files, this executable, its threads and the shipped suites' folder (adapters in {suites}/external/); the program reads the input files, writes its particles at every output "
       "time to {output}, and mpmvv computes the norms from them (reports/external-format.md)",
       -inf, inf},
      {"external_format", KeyKind::text, std::string("hdf5"),
       "what the external program writes at {output}: hdf5 (one file, a group per output time), csv or vtk (a "
       "folder, a file per output time: .csv; .vtu, .vtp or legacy .vtk); reports/external-format.md",
       -inf, inf, false, false, {"hdf5", "csv", "vtk"}},
      {"external_names", KeyKind::text, std::string(""),
       "how the external program's files name mpmvv's items, where they differ: NAME=FILE_NAME pairs separated "
       "by commas, NAME a dataset or point array of the hdf5 and vtk layouts or a column of the csv one "
       "(e.g. \"reference_volume=vol0, velocity=velocities\"; reports/external-format.md)",
       -inf, inf},
      {"external_stress_order", KeyKind::text, std::string(kVtkStressOrderText),
       "the order in which the external program's VTK files write a symmetric stress of 6 components: xx, yy, zz, "
       "xy, yz, xz each once, separated by commas (VTK's order, the default; Voigt's is \"xx, yy, zz, yz, xz, xy\"; "
       "reports/external-format.md)",
       -inf, inf},
      {"external_timeout", KeyKind::real, 0.0,
       "seconds after which the external program is ended and the case fails (0: no limit of its own; a suite's "
       "time-out still applies)",
       0.0, inf},
  };
}

std::optional<ExternalProgram> external_program(const Config& config) {
  if (!config.has("external_command")) return std::nullopt;
  if (config.text("external_command").empty()) {
    // Names describe an external program's files: without a program they
    // would be ignored, and a run the user meant for another code would read
    // as mpmvv's own.
    if (!config.text("external_names").empty())
      config.reject("external_names", "it maps the names of an external program's files, and no external_command "
                                      "names a program (set external_command, or leave external_names out)");
    if (stress_order_of(config) != kVtkStressOrder)
      config.reject("external_stress_order", "it orders the stress in an external program's files, and no "
                                             "external_command names a program (set external_command, or leave "
                                             "external_stress_order out)");
    return std::nullopt;
  }
  ExternalProgram program{config.text("external_command"), config.text("external_format"),
                          config.real("external_timeout")};
  try {
    program.names = parse_output_names(config.text("external_names"), program.format);
  } catch (const std::invalid_argument& e) {
    config.reject("external_names", e.what());
  }
  program.stress_order = stress_order_of(config);
  // Only VTK files hold a 6-component stress; another order would go unused.
  if (program.stress_order != kVtkStressOrder && program.format != "vtk")
    config.reject("external_stress_order", fmt::format("it orders a 6-component stress of VTK files, and "
                                                       "external_format is {}, whose stress has no such order",
                                                       program.format));
  return program;
}

ExternalFiles external_files(const std::string& results_path, const std::string& format) {
  fs::path stem = fs::absolute(results_path);
  stem.replace_extension();
  const std::string s = stem.string();
  return {s + ".input.json", s + ".scene.toml", s + (format == "hdf5" ? ".external.h5" : ".external"),
          s + ".external.log"};
}

namespace {

// A word the shell takes as it stands.
bool plain_word(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || std::strchr("._/+-=,:@%", c))) return false;
  return true;
}

std::string shell_quoted(const std::string& s) {
  if (plain_word(s)) return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace

std::string expand_command(const std::string& templ, const Config& config, const ExternalFiles& files,
                           const std::string& executable, int threads) {
  const std::map<std::string, std::string> own = {{"input", files.input},   {"scene", files.scene},
                                                  {"output", files.output}, {"log", files.log},
                                                  {"mpmvv", executable},    {"threads", std::to_string(threads)},
                                                  {"suites", installation().suites.string()}};
  std::string out;
  for (std::size_t i = 0; i < templ.size(); ++i) {
    const char c = templ[i];
    if ((c == '{' || c == '}') && i + 1 < templ.size() && templ[i + 1] == c) {
      out += c;
      ++i;
      continue;
    }
    if (c == '}') config.reject("external_command", fmt::format("a '}}' at character {} closes no '{{' (write }}}} for a brace)", i + 1));
    if (c != '{') {
      out += c;
      continue;
    }
    const std::size_t end = templ.find('}', i);
    if (end == std::string::npos)
      config.reject("external_command", fmt::format("the '{{' at character {} is not closed (write {{{{ for a brace)", i + 1));
    const std::string name = templ.substr(i + 1, end - i - 1);
    if (const auto o = own.find(name); o != own.end()) {
      out += shell_quoted(o->second);
    } else if (config.has(name)) {
      out += shell_quoted(as_setting(config.value(name)));
    } else {
      config.reject("external_command",
                    fmt::format("{{{}}} at character {} is neither a key of scene '{}' nor one of {{input}}, {{scene}}, "
                                "{{output}}, {{log}}, {{mpmvv}}, {{threads}}, {{suites}}",
                                name, i + 1, config.scene()));
    }
    i = end;
  }
  return out;
}

void write_external_input(const ExternalFiles& files, const Config& config, const std::vector<double>& output_times,
                          const std::vector<Vec2>& tracer_reference, const std::vector<Vec2>& tracer_start,
                          const std::string& format) {
  // The scene as mpmvv itself would run it: the program is the solver now
  // (external_format and external_timeout stay, as what the harness asked for;
  // external_names and external_stress_order are how the harness reads the
  // program's files, none of the program's business, and refused without a
  // command).
  Config own = config;
  own.set("external_command", std::string(), Origin{"external program input"});
  own.set("external_names", std::string(), Origin{"external program input"});
  own.set("external_stress_order", std::string(kVtkStressOrderText), Origin{"external program input"});
  Json keys = Json::object();
  for (const KeySpec& k : own.specs()) keys[k.name] = json_of(own.value(k.name));
  auto points = [](const std::vector<Vec2>& list) {
    Json j = Json::array();
    for (const Vec2& X : list) j.push_back({X.x(), X.y()});
    return j;
  };
  const Json input = {{"format_version", 1},
                      {"scene", config.scene()},
                      {"keys", keys},
                      {"output_times", output_times},
                      {"end_time", output_times.empty() ? 0.0 : output_times.back()},
                      {"tracer_reference", points(tracer_reference)},
                      {"tracer_start", points(tracer_start)},
                      {"output", files.output},
                      {"output_format", format},
                      {"scene_file", files.scene}};
  auto write = [](const std::string& path, const std::string& text) {
    std::ofstream f(path);
    f << text;
    f.close();
    if (!f) throw ConfigError(fmt::format("{}: cannot write the external program's input: {}", path, std::strerror(errno)));
  };
  write(files.scene, "# written by mpmvv for an external program: every key of the case (mpmvv run FILE runs it)\n" +
                         own.to_toml());
  write(files.input, json_text(input, 1) + "\n");
}

std::string ProgramEnd::describe() const {
  const std::string killed_text =
      killed ? fmt::format("; it outlived SIGTERM and was killed {:.0f} s later", seconds - ended_at) : "";
  if (timed_out) return fmt::format("ended after {:.0f} s (external_timeout){}", ended_at, killed_text);
  if (stopped) return fmt::format("ended after {:.0f} s: mpmvv was asked to stop{}", ended_at, killed_text);
  if (signal) return fmt::format("killed by signal {} ({})", signal, strsignal(signal));
  return fmt::format("exit status {}", exit_status);
}

namespace {

// The last `count` lines of a file, for a message.
std::string tail_of(const std::string& path, std::size_t count) {
  std::ifstream f(path);
  std::deque<std::string> lines;
  for (std::string line; std::getline(f, line);) {
    lines.push_back(line);
    if (lines.size() > count) lines.pop_front();
  }
  std::string s;
  for (const std::string& l : lines) s += (s.empty() ? "" : "\n") + l;
  return s;
}

}  // namespace

ProgramEnd run_program(const std::string& command, const std::string& log_path, double timeout,
                       const std::function<void(double seconds)>& tick) {
  const int log = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log < 0) throw std::runtime_error(fmt::format("{}: cannot open the external program's log: {}", log_path, std::strerror(errno)));
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(log);
    throw std::runtime_error(fmt::format("cannot start the external program: fork: {}", std::strerror(errno)));
  }
  if (pid == 0) {
    // The child: its own process group (ended whole), ended with mpmvv, its
    // output into the log, stdin empty.
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(127);
    const int null = ::open("/dev/null", O_RDONLY);
    if (null >= 0) ::dup2(null, 0);
    ::dup2(log, 1);
    ::dup2(log, 2);
    ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    ::dprintf(2, "mpmvv: cannot run /bin/sh: %s\n", std::strerror(errno));
    ::_exit(127);
  }
  ::close(log);
  ::setpgid(pid, pid);  // also from here, so the group exists before any kill below
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  auto seconds = [&] { return std::chrono::duration<double>(clock::now() - start).count(); };
  ProgramEnd end;
  double told = 0.0, ending_since = -1.0;
  int status = 0;
  while (true) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0 && errno != EINTR) throw std::runtime_error(fmt::format("waiting for the external program: {}", std::strerror(errno)));
    const double s = seconds();
    if (ending_since < 0.0) {
      end.timed_out = timeout > 0.0 && s > timeout;
      end.stopped = stop_request().load(std::memory_order_relaxed);
      if (end.timed_out || end.stopped) {
        ::kill(-pid, SIGTERM);
        ending_since = s;
        end.ended_at = s;
      }
    } else if (s - ending_since > 5.0) {
      ::kill(-pid, SIGKILL);
      end.killed = true;
    }
    if (tick && s - told >= 1.0) {
      told = s;
      tick(s);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  end.seconds = seconds();
  if (WIFEXITED(status)) end.exit_status = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) end.signal = WTERMSIG(status);
  end.log_tail = tail_of(log_path, 5);
  return end;
}

}  // namespace mpmvv::app
