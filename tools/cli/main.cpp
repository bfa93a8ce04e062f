// mpmvv: the command line. Each command is a thin layer over tools/app.
#include <CLI/CLI.hpp>

#include <iostream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "tools/app/config.hpp"
#include "tools/app/run_case.hpp"

namespace {

std::string joined(int argc, char** argv) {
  std::string s;
  for (int i = 0; i < argc; ++i) s += (i ? " " : "") + std::string(argv[i]);
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mpmvv: verification and validation of a compact MPM/CPDI solver.\n"
               "Exit status: 0 success, 1 a run or check fell short, 2 bad input."};
  app.set_version_flag("--version", mpmvv::app::version_string());
  app.require_subcommand(1);

  mpmvv::app::RunRequest run;
  CLI::App* run_cmd = app.add_subcommand(
      "run", "Run one case of a scene and write its results file.\n"
             "Exit status: 0 completed, 1 the solver stopped the run (results still written with status "
             "\"failed\"), 2 bad input.");
  run_cmd->add_option("scene", run.scene_file, "scene file (TOML), e.g. suites/scenes/ring.toml")->required();
  run_cmd->add_option("--set", run.overrides, "override a scene key: --set cells=128 (repeatable)")
      ->allow_extra_args(false)
      ->type_name("KEY=VALUE");
  run_cmd->add_option("-o,--output", run.output, "results file (.h5); default: <scene name>.h5")->type_name("FILE");
  run_cmd->add_option("-t,--threads", run.threads, "OpenMP threads (default: all cores)")->check(CLI::NonNegativeNumber);
  run_cmd->add_flag("-q,--quiet", run.quiet, "no configuration echo and no progress line");
  run_cmd->add_flag("--describe", run.describe, "print every key of the scene with its value and meaning, then stop");

  app.add_subcommand("scenes", "List the scenes and the keys each accepts.");

  if (argc > 1 && argv[1][0] != '-') {
    bool known = false;
    std::string commands;
    for (const CLI::App* sub : app.get_subcommands({})) {
      known = known || sub->get_name() == argv[1];
      commands += (commands.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known) {
      fmt::print(stderr, "mpmvv: unknown command '{}' (commands: {}; see mpmvv --help)\n", argv[1], commands);
      return 2;
    }
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
    for (const CLI::App* sub : app.get_subcommands()) where += " " + sub->get_name();
    fmt::print(stderr, "{}: {} (see {} --help)\n", where, e.what(), where);
    return 2;
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
    return mpmvv::app::run_case(run, std::cout, std::cerr);
  }
  return 2;
}
