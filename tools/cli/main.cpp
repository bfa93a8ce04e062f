// mpmvv: the command line. Each command is a thin layer over tools/app.
#include <CLI/CLI.hpp>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "tools/app/config.hpp"
#include "tools/app/material_drive.hpp"
#include "tools/app/mms_command.hpp"
#include "tools/app/suite/suite.hpp"
#include "tools/app/installation.hpp"
#include "tools/app/run_case.hpp"

namespace {

std::string joined(int argc, char** argv) {
  std::string s;
  for (int i = 0; i < argc; ++i) s += (i ? " " : "") + std::string(argv[i]);
  return s;
}

// OpenMP threads that spin while they wait for each other take the cores
// from whatever else runs: two 2-thread runs of the ring on 128 cells side by
// side on 2 cores took 1.90 s spinning and 0.92 s waiting passively (one
// thread each: 0.86 s), while one such run alone on idle cores took 0.53 s
// and 0.59 s (on 256 cells 1.30 s and 1.22 s). libgomp reads
// OMP_WAIT_POLICY once, as it loads, so a run without a policy of its own
// is started again with "passive"; one that names a policy (or libgomp's
// GOMP_SPINCOUNT) keeps it. Should the restart fail, the run goes on as it
// is, with libgomp's default.
void wait_passively_unless_told(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr || std::getenv("GOMP_SPINCOUNT") != nullptr) return;
  if (setenv("OMP_WAIT_POLICY", "passive", 1) != 0) return;
  execv("/proc/self/exe", argv);
  unsetenv("OMP_WAIT_POLICY");  // not restarted: the policy loaded is the default, say so
}

}  // namespace

// CLI11's number checks let NaN through (every comparison with it is false):
// a time or a duration must be a finite number.
const CLI::Validator kFinite(
    [](std::string& text) {
      const double value = std::strtod(text.c_str(), nullptr);
      return std::isfinite(value) ? std::string() : "must be a finite number, not " + text;
    },
    "FINITE");

// CLI11's PositiveNumber and NonNegativeNumber say "Value 0 not in range
// 0.000000 to 1.79769e+308", a range 0 is inside of: say the rule instead.
const CLI::Validator kPositive(
    [](std::string& text) {
      return std::strtod(text.c_str(), nullptr) > 0.0 ? std::string() : "must be a positive number, not " + text;
    },
    "POSITIVE");
const CLI::Validator kNonNegative(
    [](std::string& text) {
      return std::strtod(text.c_str(), nullptr) >= 0.0 ? std::string() : "must be 0 or more, not " + text;
    },
    "NON-NEGATIVE");

// A word where a command is due that names none ("mpmvv nope", "mpmvv
// results nope", "mpmvv --nope"): CLI11 would say only that a subcommand is
// required. Empty when every command named is known.
std::string unknown_command(const CLI::App& app, int argc, char** argv) {
  const CLI::App* at = &app;
  std::string where = "mpmvv";
  for (int i = 1; i < argc && !at->get_subcommands({}).empty() && at->get_require_subcommand_min() > 0; ++i) {
    const std::string word = argv[i];
    if (word == "-h" || word == "--help" || word == "--help-all" || word == "--version") return {};
    std::string commands;
    const CLI::App* next = nullptr;
    for (const CLI::App* sub : at->get_subcommands({})) {
      if (sub->get_name() == word) next = sub;
      commands += (commands.empty() ? "" : ", ") + sub->get_name();
    }
    if (!next)
      return fmt::format("{}: unknown {} '{}' (commands: {}; see {} --help)", where,
                         word.rfind('-', 0) == 0 ? "option" : "command", word, commands, where);
    where += " " + word;
    at = next;
  }
  return {};
}

int main(int argc, char** argv) {
  wait_passively_unless_told(argv);
  CLI::App app{"mpmvv: verification and validation of a compact MPM/CPDI solver.\n"
               "Exit status: 0 success, 1 a run or check fell short, 2 bad input."};
  app.set_version_flag("--version", mpmvv::app::version_string());
  app.require_subcommand(1);

  mpmvv::app::RunRequest run;
  CLI::App* run_cmd = app.add_subcommand(
      "run", "Run one case of a scene and write its results file.\n"
             "Exit status: 0 completed, 1 the solver stopped the run (results still written with status "
             "\"failed\") or it ran to its end with its solution lost (status \"lost\": the health verdict, "
             "keys health_J_factor and health_energy_loss_factor), 2 bad input or a results file that could not be "
             "written (a full disk: the reason is named, no file is left).");
  run_cmd->add_option("scene", run.scene_file, "scene file (TOML), e.g. suites/scenes/ring.toml")->required();
  run_cmd->add_option("--set", run.overrides, "override a scene key: --set cells=128 (repeatable)")
      ->allow_extra_args(false)
      ->type_name("KEY=VALUE");
  run_cmd->add_option("-o,--output", run.output, "results file (.h5); default: <scene name>.h5")->type_name("FILE");
  run_cmd->add_option("-t,--threads", run.threads,
                      "OpenMP threads (default: all cores); they wait passively for each other unless "
                      "OMP_WAIT_POLICY says otherwise (OMP_WAIT_POLICY=active spins: a few percent faster on idle "
                      "cores, twice as slow or worse beside other work)")->check(CLI::Range(0, 1024));
  run_cmd->add_flag("-q,--quiet", run.quiet, "no configuration echo and no progress line");
  run_cmd->add_flag("--describe", run.describe, "print every key of the scene with its value and meaning, then stop");
  run_cmd->add_option("--checkpoint-every", run.checkpoint_every,
                      "save the run's state to FILE.restart (FILE the results file) every SECONDS of wall time and "
                      "when it is stopped early (a signal, --pause-at), for --resume")
      ->type_name("SECONDS")
      ->check(kFinite & kPositive);
  run_cmd->add_option("--pause-at", run.pause_at,
                      "stop before the first step from simulated time T on, as interrupted, saving its state to "
                      "FILE.restart for --resume")
      ->type_name("T")
      ->check(kFinite & kNonNegative);
  bool resume = false, resume_if_same = false;
  CLI::Option* resume_flag = run_cmd->add_flag("--resume", resume,
                    "go on from FILE.restart when it exists, to the bits of a run that never stopped (refused when it "
                    "holds another configuration, build or thread count); start from t = 0 when it does not");
  run_cmd->add_flag("--resume-if-same", resume_if_same,
                    "as --resume, but start from t = 0 when FILE.restart holds another run's state (what a suite "
                    "passes)")
      ->excludes(resume_flag);

  app.add_subcommand("scenes", "List the scenes and the keys each accepts.");
  app.add_subcommand("paths", "Where this mpmvv finds its reports package and the shipped suites and scene files "
                             "(installed under its prefix's share/mpmvv, or the source tree it was built from).");

  mpmvv::app::SuiteRequest suite;
  CLI::App* suite_cmd = app.add_subcommand(
      "suite", "Run every case of a suite, each in a process of its own; resumable; shares cases over MPI ranks under "
               "mpirun.\nExit status: 0 every case completed, lost its solution or was stopped by the solver, 1 a case "
               "crashed, timed out or was refused (or the suite could not write its own files: a full disk; rerun to "
               "resume), 2 bad input (also: another suite running in DIR, or DIR holding "
               "another suite's results without --force), 130 interrupted (rerun to resume).");
  suite_cmd->add_option("suite", suite.suite_file, "suite file (TOML), e.g. suites/ring-quick.toml")->required();
  suite_cmd->add_option("-j,--jobs", suite.jobs, "cases at once (per MPI rank)")->check(CLI::Range(1, 1024));
  suite_cmd->add_option("-t,--threads", suite.threads,
                        "OpenMP threads per case (default: the cores shared out over the cases at once, at least 1); "
                        "set it when two suites share the machine")
      ->check(CLI::Range(1, 1024));
  suite_cmd->add_option("-o,--output", suite.output_dir, "output directory; default results/<suite name>")->type_name("DIR");
  suite_cmd->add_flag("-q,--quiet", suite.quiet, "no progress");
  suite_cmd->add_flag("--list", suite.list,
                      "check the suite and list its cases with their settings and estimated run times; run nothing");
  suite_cmd->add_option("--tier", suite.tier,
                        "which tier of the suite: 'full' (the whole study) or 'ci' (the cheap tier every merge runs: "
                        "its studies' `ci` tables and the expectations marked tier = \"ci\"); default full, output "
                        "in results/<suite name>-ci for ci")
      ->type_name("TIER");
  suite_cmd->add_option("--budget", suite.budget_seconds,
                        "a wall time in seconds: say which cases a run of that length (with -j) will not reach, from "
                        "the estimates --list prints")
      ->type_name("SECONDS")
      ->check(kFinite & kPositive);
  suite_cmd->add_option("--only", suite.only,
                        "run (or list) only the cases whose id this regular expression finds, e.g. 'cells=(300|600)-'; "
                        "the others stay as an earlier run left them (pending, or kept)")
      ->type_name("REGEX");
  suite_cmd->add_flag("--force", suite.force,
                      "run in an output directory that holds another suite's results (its manifest is replaced and "
                      "its cases are no longer listed)");

  std::string report_dir, report_out;
  CLI::App* report_cmd = app.add_subcommand(
      "report", "Tables, figures, report.html, report.md, orders.csv and levels.csv from a suite's results (no solver runs).");
  report_cmd->add_option("dir", report_dir, "suite output directory")->required();
  report_cmd->add_option("-o,--output", report_out, "where to write; default DIR/report")->type_name("DIR");
  bool report_quiet = false;
  report_cmd->add_flag("-q,--quiet", report_quiet, "no progress lines (a line per study on stderr)");
  std::string gate_dir;
  CLI::App* gate_cmd = app.add_subcommand(
      "gate", "Check every expectation of a suite against its results.\nExit status: 0 all hold, 1 some fell short "
              "(with a table), 2 bad input.");
  gate_cmd->add_option("dir", gate_dir, "suite output directory")->required();
  std::string gate_junit, gate_json;
  gate_cmd->add_option("--junit", gate_junit, "also write the verdicts as JUnit XML, one test case per expectation "
                                              "and series (GitLab, Jenkins, GitHub Actions)")->type_name("FILE");
  gate_cmd->add_option("--json", gate_json, "also write the verdicts with every number of their rows as JSON")
      ->type_name("FILE");

  std::vector<std::string> results_files;
  CLI::App* results_cmd = app.add_subcommand("results", "Results files: check one against the documented format.");
  results_cmd->require_subcommand(1);
  CLI::App* results_check_cmd = results_cmd->add_subcommand(
      "check", "Name every missing or malformed item of results files (reports/results-format.md).\nExit status: 0 "
               "every file follows the format, 1 some item is missing or malformed, 2 a file is not HDF5.");
  results_check_cmd->add_option("files", results_files, "results files")->required();
  CLI::App* mms_cmd = app.add_subcommand("mms", "Manufactured solutions: list them, evaluate one, check its body force.");
  mms_cmd->require_subcommand(1);
  mms_cmd->add_subcommand("list", "The manufactured solutions and their parameters.");
  mpmvv::app::MmsEvalRequest eval;
  CLI::App* eval_cmd = mms_cmd->add_subcommand(
      "eval", "Exact fields and body force of a solution at one reference point.\nExit status: 0, or 2 on bad input.");
  eval_cmd->add_option("name", eval.name, "solution name (mpmvv mms list)")->required();
  eval_cmd->add_option("--at", eval.at, "reference point X,Y (R,Z in r-z)")
      ->required()
      ->delimiter(',')
      ->expected(2)
      ->check(kFinite);
  eval_cmd->add_option("--time", eval.time, "time t [s]")->required()->check(kFinite);
  eval_cmd->add_option("--set", eval.overrides, "override a parameter: --set amplitude=1 (repeatable)")
      ->allow_extra_args(false)
      ->type_name("KEY=VALUE");
  eval_cmd->add_flag("--json", eval.json, "one JSON object instead of text");
  mpmvv::app::MmsCheckRequest check;
  CLI::App* check_cmd = mms_cmd->add_subcommand(
      "check", "Residual a - Div P / rho_0 - b at random points, by finite differences independent of the "
               "derived force.\nExit status: 0 within tolerance, 1 above, 2 bad input.");
  check_cmd->add_option("name", check.name, "solution name (mpmvv mms list)")->required();
  check_cmd->add_option("--points", check.points, "random points")->check(CLI::Range(1, 10000000));
  check_cmd->add_option("--tolerance", check.tolerance,
                        "largest allowed relative residual (default: 3 times the differences' own error, estimated "
                        "from two step sizes)")
      ->check(kFinite & kPositive);
  check_cmd->add_option("--seed", check.seed, "random seed");
  check_cmd->add_option("--set", check.overrides, "override a parameter (repeatable)")
      ->allow_extra_args(false)
      ->type_name("KEY=VALUE");

  CLI::App* material_cmd = app.add_subcommand(
      "material", "The material-point driver: each material under F-tables, against its exact stress and energy.");
  material_cmd->require_subcommand(1);
  material_cmd->add_subcommand("tables", "The standard F-tables and the table file's format.");
  mpmvv::app::MaterialDriveRequest drive;
  CLI::App* drive_cmd = material_cmd->add_subcommand(
      "drive", "Drive every material (or --material) through F-tables, unrotated and under a superimposed rotation, "
               "and compare its stress and energy with the principal-stretch forms, its energy's derivative, the "
               "work along the path and the rotated stress.\nExit status: 0 every check within tolerance, 1 some "
               "check above, 2 bad input.");
  drive_cmd->add_option("--material", drive.materials, "neo-hookean, mooney-rivlin or linear-elastic (repeatable)");
  drive_cmd->add_option("--table", drive.tables, "a standard F-table (mpmvv material tables) or a table file (repeatable)");
  drive_cmd->add_option("--rotation", drive.rotation_degrees, "superimposed rotation at the path's end [deg]; 0: none")
      ->check(kFinite);
  drive_cmd->add_option("--steps", drive.steps, "samples along a standard table's path")->check(CLI::Range(2, 1000000));
  drive_cmd->add_option("--tolerance", drive.tolerance, "largest relative error a check allows")
      ->check(kFinite & kPositive);
  drive_cmd->add_option("--set", drive.overrides, "a material key: --set lambda=1e3 (repeatable; mpmvv run --describe)")
      ->allow_extra_args(false)
      ->type_name("KEY=VALUE");
  drive_cmd->add_option("--json", drive.json, "also write the rows and the parameters as JSON to this file");

  if (const std::string unknown = unknown_command(app, argc, argv); !unknown.empty()) {
    fmt::print(stderr, "{}\n", unknown);
    return 2;
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::string where = "mpmvv";
    for (const CLI::App* at = &app; !at->get_subcommands().empty();) {
      at = at->get_subcommands().front();
      where += " " + at->get_name();
    }
    fmt::print(stderr, "{}: {} (see {} --help)\n", where, e.what(), where);
    return 2;
  }

  if (mms_cmd->parsed()) {
    if (mms_cmd->got_subcommand("list")) {
      std::cout << mpmvv::app::mms_list();
      return 0;
    }
    if (eval_cmd->parsed()) return mpmvv::app::mms_eval(eval, std::cout, std::cerr);
    if (check_cmd->parsed()) return mpmvv::app::mms_check(check, std::cout, std::cerr);
  }
  if (material_cmd->parsed()) {
    if (drive_cmd->parsed()) return mpmvv::app::material_drive(drive, std::cout, std::cerr);
    std::cout << mpmvv::app::material_tables();
    return 0;
  }
  if (suite_cmd->parsed()) return mpmvv::app::run_suite(suite, std::cout, std::cerr);
  if (report_cmd->parsed()) {
    std::vector<std::string> args = {report_dir};
    // Passed whenever given, an empty one too: the tool refuses it by name.
    if (report_cmd->count("--output")) args.insert(args.end(), {"-o", report_out});
    if (report_quiet) args.push_back("--quiet");
    return mpmvv::app::run_report_tool("report", args, std::cerr);
  }
  if (results_check_cmd->parsed()) return mpmvv::app::run_report_tool("results_check", results_files, std::cerr);
  if (gate_cmd->parsed()) {
    std::vector<std::string> args = {gate_dir};
    if (gate_cmd->count("--junit")) args.insert(args.end(), {"--junit", gate_junit});
    if (gate_cmd->count("--json")) args.insert(args.end(), {"--json", gate_json});
    return mpmvv::app::run_report_tool("gate", args, std::cerr);
  }
  if (app.got_subcommand("paths")) {
    const mpmvv::app::Installation where = mpmvv::app::installation();
    const char* from = where.installed ? "installed" : "source tree";
    fmt::print("reports {} ({})\nsuites  {} ({})\nscenes  {} ({})\n", where.reports.string(), from,
               where.suites.string(), from, (where.suites / "scenes").string(), from);
    return 0;
  }
  if (app.got_subcommand("scenes")) {
    std::cout << mpmvv::app::describe_scenes();
    return 0;
  }
  if (run_cmd->parsed()) {
    if (run.describe) {
      try {
        std::cout << mpmvv::app::describe_configuration(run.scene_file, run.overrides);
        return 0;
      } catch (const mpmvv::app::ConfigError& e) {
        fmt::print(stderr, "mpmvv run: {}\n", e.what());
        return 2;
      }
    }
    run.command_line = joined(argc, argv);
    run.resume = resume           ? mpmvv::app::RunRequest::Resume::yes
                 : resume_if_same ? mpmvv::app::RunRequest::Resume::if_same
                                  : mpmvv::app::RunRequest::Resume::no;
    return mpmvv::app::run_case(run, std::cout, std::cerr);
  }
  return 2;
}
