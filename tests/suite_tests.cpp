// The suite runner keeps every case in a process of its own, resumes, shares
// cases over MPI ranks; the gate catches real faults (the suite file's own
// checks: suite_file_tests.cpp). These tests run whole suites through the
// built `mpmvv`, so ctest runs them one at a time.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <thread>

#include "solver/io/hdf5.hpp"
#include "suite_support.hpp"
#include "tools/app/config.hpp"
#include "tools/app/suite/suite.hpp"

namespace {

using namespace mpmvv::suite_testing;

// Three quick cases of the axis-aligned problem.
std::string small_suite(double timeout = 120) {
  return "timeout = " + std::to_string(timeout) + "\n[[study]]\nname = \"square\"\nscene = \"" + kScenes +
         "/axis-aligned.toml\"\nset = { end_time = 0.005, output_times = [0.005] }\nsweep = { cells = [8, 12, 16] }\n";
}

}  // namespace

// A case that crashes or hangs fails alone: the others complete, the manifest
// says which ended how, no half-written results file remains, exit status 1.
TEST(SuiteRunner, CrashAndHangAreIsolated) {
  const fs::path dir = scratch("isolation");
  const fs::path suite = write(dir / "s.toml", small_suite(3));
  const int status = shell("MPMVV_FAULT=crash MPMVV_FAULT_ONLY=cells=12 " + std::string(MPMVV_BINARY) + " suite " +
                           suite.string() + " -j 2 -q -o " + (dir / "out").string());
  EXPECT_EQ(status, 1);
  const std::string manifest = read(dir / "out" / "manifest.json");
  EXPECT_EQ(cases_with_status(manifest, "completed"), 2) << manifest;
  EXPECT_EQ(cases_with_status(manifest, "crashed"), 1) << manifest;
  EXPECT_TRUE(fs::exists(dir / "out/cases/square-cells=8.h5"));
  EXPECT_FALSE(fs::exists(dir / "out/cases/square-cells=12.h5"));

  const int hung = shell("MPMVV_FAULT=hang MPMVV_FAULT_ONLY=cells=16 " + std::string(MPMVV_BINARY) + " suite " +
                         suite.string() + " -j 2 -q -o " + (dir / "hang").string());
  EXPECT_EQ(hung, 1);
  const std::string hang_manifest = read(dir / "hang" / "manifest.json");
  EXPECT_EQ(cases_with_status(hang_manifest, "timeout"), 1) << hang_manifest;
  EXPECT_EQ(cases_with_status(hang_manifest, "completed"), 2) << hang_manifest;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    EXPECT_EQ(entry.path().string().find(".partial"), std::string::npos) << entry.path();
}

// A case past the suite's timeout ends with its external program's whole
// process group, the program's own background children included: the suite
// sends the case SIGTERM, and the case ends the group it started.
TEST(SuiteRunner, ATimedOutExternalProgramLeavesNoProcessBehind) {
  const fs::path dir = scratch("external-timeout");
  const std::string marker = "317." + std::to_string(::getpid());
  const fs::path suite = write(dir / "s.toml", "timeout = 2\n[[study]]\nname = \"slow\"\nscene = \"" + kScenes +
                                                 "/ring.toml\"\nset = { external_command = \"sleep " + marker +
                                                 " & sleep " + marker + "\" }\n");
  const int status = shell(std::string(MPMVV_BINARY) + " suite " + suite.string() + " -j 1 -q -o " +
                           (dir / "out").string());
  EXPECT_EQ(status, 1);
  EXPECT_EQ(cases_with_status(read(dir / "out" / "manifest.json"), "timeout"), 1);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_NE(shell("pgrep -f 'slee[p] " + marker + "' > /dev/null"), 0) << "a sleep " << marker << " survived the suite";
  shell("pkill -f 'slee[p] " + marker + "'");
}

// The manifest and each case's file are JSON that a reader parses back to
// what the suite holds: a description with quotes, a backslash, a tab, a
// newline and a non-ASCII letter, keys as numbers and strings, a crashed
// case's status and exit code.
TEST(SuiteRunner, TheManifestIsJsonWhateverItsTextsHold) {
  const fs::path dir = scratch("json");
  // TOML's escapes in the file; the same characters in `description`.
  const std::string description = "the \"square\" \\ at\tonce\nand \u00e9";
  const fs::path suite =
      write(dir / "s.toml", R"(description = "the \"square\" \\ at\tonce\nand \u00e9")" "\n" + small_suite(30));
  const int status = shell("MPMVV_FAULT=crash MPMVV_FAULT_ONLY=cells=12 " + std::string(MPMVV_BINARY) + " suite " +
                           suite.string() + " -j 2 -q -o " + (dir / "out").string());
  EXPECT_EQ(status, 1);
  const nlohmann::json manifest =
      nlohmann::json::parse(read(dir / "out" / "manifest.json"), nullptr, /*allow_exceptions=*/false);
  ASSERT_TRUE(manifest.is_object()) << read(dir / "out" / "manifest.json");
  EXPECT_EQ(manifest["suite"], "s");
  EXPECT_EQ(manifest["description"], description);
  ASSERT_EQ(manifest["cases"].size(), 3u);
  for (const nlohmann::json& c : manifest["cases"]) {
    const std::string id = c["id"];
    const nlohmann::json own = nlohmann::json::parse(read(dir / "out" / "cases" / (id + ".json")), nullptr, false);
    EXPECT_EQ(own, c) << id;
    EXPECT_TRUE(c["keys"]["cells"].is_number_integer()) << c;
    EXPECT_EQ(c["keys"]["variant"], "2d") << c;
    EXPECT_TRUE(c["wall_time_s"].is_number()) << c;
    const bool crashed = c["keys"]["cells"] == 12;
    EXPECT_EQ(c["status"], crashed ? "crashed" : "completed") << c;
    if (crashed) {
      EXPECT_NE(c["exit_code"], 0) << c;
    }
  }
}

// A rerun keeps every case whose results file holds the same configuration
// and runs only what is missing or changed.
TEST(SuiteRunner, ResumeRunsOnlyWhatIsMissing) {
  const fs::path dir = scratch("resume");
  const fs::path suite = write(dir / "s.toml", small_suite());
  const std::string run = std::string(MPMVV_BINARY) + " suite " + suite.string() + " -j 2 -q -o " + (dir / "out").string();
  ASSERT_EQ(shell(run), 0);
  const fs::path kept = dir / "out/cases/square-cells=8.h5";
  const auto written = fs::last_write_time(kept);
  fs::remove(dir / "out/cases/square-cells=16.h5");
  ASSERT_EQ(shell(run), 0);
  const std::string manifest = read(dir / "out" / "manifest.json");
  EXPECT_EQ(count(manifest, "kept from an earlier run"), 2) << manifest;
  EXPECT_EQ(cases_with_status(manifest, "completed"), 3) << manifest;
  EXPECT_EQ(fs::last_write_time(kept), written);
  EXPECT_TRUE(fs::exists(dir / "out/cases/square-cells=16.h5"));
  // A changed configuration is not kept.
  write(suite, small_suite() + "[[study.override]]\nwhere = { cells = 8 }\nset = { cfl = 0.25 }\n");
  ASSERT_EQ(shell(run), 0);
  EXPECT_EQ(count(read(dir / "out" / "manifest.json"), "kept from an earlier run"), 2);
}

// With checkpoint_every, a case the suite stops (an interrupted suite sends it
// SIGTERM) saves its state, and the rerun goes on from it: the case ends with
// the bits of the same run made in one piece, and records where it went on
// from.
TEST(SuiteRunner, ACaseStoppedPartWayGoesOnFromItsSavedState) {
  const fs::path dir = scratch("checkpoints");
  const std::string set = "{ cells = 256, amplitude = 0.5, end_time = 0.6, output_times = [0.3, 0.6] }";
  const fs::path suite = write(dir / "s.toml", "checkpoint_every = 0.5\n[[study]]\nname = \"ring\"\nscene = \"" +
                                                   kScenes + "/ring.toml\"\nset = " + set + "\n");
  const fs::path out = dir / "out";
  const fs::path results = out / "cases/ring.h5";
  const std::string state = results.string() + ".restart";
  const std::string run = std::string(MPMVV_BINARY) + " suite " + suite.string() + " -j 1 -t 1 -q -o " + out.string();
  // Stopped once its state has been saved (or after 60 s).
  const int status = shell("sh -c '" + run + " & suite=$!; for i in $(seq 600); do [ -e " + state +
                           " ] && break; sleep 0.1; done; kill -INT $suite; wait $suite'");
  EXPECT_EQ(status, 130);
  ASSERT_TRUE(fs::exists(state)) << "no state saved";
  double stopped_at = 0.0;
  {
    const mpmvv::h5::File f = mpmvv::h5::File::open_read(results.string());
    EXPECT_EQ(f.root().attribute_string("status"), "interrupted");
    stopped_at = f.root().attribute_double("time_reached");
  }
  ASSERT_EQ(shell(run), 0);
  EXPECT_FALSE(fs::exists(state));
  const fs::path whole = dir / "whole.h5";
  ASSERT_EQ(shell(std::string(MPMVV_BINARY) + " run " + kScenes + "/ring.toml -q -t 1 --set cells=256 --set " +
                  "amplitude=0.5 --set end_time=0.6 --set output_times=[0.3,0.6] -o " + whole.string()),
            0);
  const mpmvv::h5::File a = mpmvv::h5::File::open_read(results.string());
  const mpmvv::h5::File b = mpmvv::h5::File::open_read(whole.string());
  const std::vector<double> resumed_at = a.root().attribute_doubles("resumed_at");
  ASSERT_EQ(resumed_at.size(), 1u);
  EXPECT_GT(resumed_at[0], 0.0);
  EXPECT_LE(resumed_at[0], stopped_at);
  EXPECT_EQ(a.root().attribute_int("steps"), b.root().attribute_int("steps"));
  for (const char* name : {"position", "velocity", "deformation_gradient"}) {
    const std::vector<double> x = a.root().open_group("particles").read_doubles(name);
    const std::vector<double> y = b.root().open_group("particles").read_doubles(name);
    ASSERT_EQ(x.size(), y.size()) << name;
    EXPECT_EQ(std::memcmp(x.data(), y.data(), x.size() * sizeof(double)), 0) << name;
  }
  EXPECT_EQ(a.root().open_group("errors").read_doubles("L1_theta0"),
            b.root().open_group("errors").read_doubles("L1_theta0"));
}

// A rerun does not keep a results file made with a deliberate fault when none
// is asked for now, nor one without its error table: both run again.
TEST(SuiteRunner, ResumeRunsFaultedAndDamagedResultsAgain) {
  const fs::path dir = scratch("resume-faulted");
  const fs::path suite = write(dir / "s.toml", small_suite());
  const std::string run = std::string(MPMVV_BINARY) + " suite " + suite.string() + " -j 2 -q -o " + (dir / "out").string();
  ASSERT_EQ(shell("MPMVV_FAULT=no-body-force MPMVV_FAULT_ONLY=cells=8 " + run), 0);
  const fs::path faulted = dir / "out/cases/square-cells=8.h5";
  ASSERT_TRUE(mpmvv::h5::File::open_read(faulted.string()).root().has_attribute("fault_injected"));
  ASSERT_EQ(shell(run), 0);
  std::string manifest = read(dir / "out" / "manifest.json");
  EXPECT_EQ(count(manifest, "kept from an earlier run"), 2) << manifest;
  EXPECT_FALSE(mpmvv::h5::File::open_read(faulted.string()).root().has_attribute("fault_injected"));
  // The same fault asked for again keeps the file made with it.
  ASSERT_EQ(shell("MPMVV_FAULT=no-body-force MPMVV_FAULT_ONLY=cells=8 " + run), 0);
  ASSERT_EQ(shell("MPMVV_FAULT=no-body-force MPMVV_FAULT_ONLY=cells=8 " + run), 0);
  EXPECT_EQ(count(read(dir / "out" / "manifest.json"), "kept from an earlier run"), 3);
  // A results file whose /errors group is gone.
  ASSERT_EQ(shell(run), 0);
  const fs::path damaged = dir / "out/cases/square-cells=12.h5";
  {
    const hid_t file = H5Fopen(damaged.string().c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(file, 0);
    EXPECT_GE(H5Ldelete(file, "errors", H5P_DEFAULT), 0);
    H5Fclose(file);
  }
  ASSERT_EQ(shell(run), 0);
  manifest = read(dir / "out" / "manifest.json");
  EXPECT_EQ(count(manifest, "kept from an earlier run"), 2) << manifest;
  EXPECT_TRUE(mpmvv::h5::File::open_read(damaged.string()).root().has("errors"));
  // A results file written before the health verdict (no attribute health):
  // it could read "completed" with its solution lost, so it runs again.
  const fs::path old = dir / "out/cases/square-cells=16.h5";
  {
    const hid_t file = H5Fopen(old.string().c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(file, 0);
    EXPECT_GE(H5Adelete(file, "health"), 0);
    H5Fclose(file);
  }
  ASSERT_EQ(shell(run), 0);
  manifest = read(dir / "out" / "manifest.json");
  EXPECT_EQ(count(manifest, "kept from an earlier run"), 2) << manifest;
  EXPECT_TRUE(mpmvv::h5::File::open_read(old.string()).root().has_attribute("health"));
}

// A full disk, made here by a partial file that is a link to /dev/full
// (every write to it fails with ENOSPC). A run whose results cannot be
// written ends with one line and exit 2, not a crash, and leaves no file; a
// suite whose manifest cannot be written stops with one line and exit 1,
// keeps the results it finished and the last manifest it wrote (valid JSON),
// and a rerun once there is room resumes.
TEST(SuiteRunner, AFullDiskEndsACaseOrTheSuiteWithOneLine) {
  const fs::path dir = scratch("full-disk");
  const fs::path out = dir / "out";
  fs::create_directories(out);
  const fs::path message = dir / "message.txt";
  fs::create_symlink("/dev/full", out / "r.h5.partial");
  const std::string run_one = std::string(MPMVV_BINARY) + " run " + kScenes +
                              "/axis-aligned.toml --set cells=8 --set end_time=0.005 --set output_times=[0.005] -q -o " +
                              (out / "r.h5").string();
  int status = std::system((run_one + " > /dev/null 2> " + message.string()).c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << read(message);
  EXPECT_EQ(count(read(message), "\n"), 1) << read(message);
  EXPECT_NE(read(message).find("No space left on device"), std::string::npos) << read(message);
  EXPECT_FALSE(fs::exists(out / "r.h5"));
  EXPECT_FALSE(fs::is_symlink(out / "r.h5.partial"));

  const fs::path suite = write(dir / "s.toml", small_suite());
  const std::string run = std::string(MPMVV_BINARY) + " suite " + suite.string() + " -j 1 -q -o " + out.string();
  ASSERT_EQ(shell(run + " --only 'cells=8$'"), 0);
  fs::create_symlink("/dev/full", out / "manifest.json.partial");
  status = std::system((run + " > /dev/null 2> " + message.string()).c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << read(message);
  EXPECT_NE(read(message).find("manifest.json.partial (write): No space left on device; the suite stopped"),
            std::string::npos)
      << read(message);
  // The manifest the first run wrote, whole: case 8 completed, the others pending.
  const std::string manifest = read(out / "manifest.json");
  ASSERT_GE(manifest.size(), 4u);
  EXPECT_EQ(manifest.substr(manifest.size() - 4), "\n]}\n") << manifest;
  EXPECT_EQ(cases_with_status(manifest, "completed"), 1) << manifest;
  EXPECT_EQ(cases_with_status(manifest, "pending"), 2) << manifest;
  // The case that finished before the manifest failed (-j 1: the first) is kept.
  EXPECT_TRUE(fs::exists(out / "cases/square-cells=12.h5"));
  fs::remove(out / "manifest.json.partial");
  ASSERT_EQ(shell(run), 0);
  const std::string resumed = read(out / "manifest.json");
  EXPECT_EQ(cases_with_status(resumed, "completed"), 3) << resumed;
  EXPECT_EQ(count(resumed, "kept from an earlier run"), 2) << resumed;
}

// --only runs the cases whose id the regular expression finds and leaves the
// others pending, to be run (or kept) by a later run; a bad expression is bad
// input.
TEST(SuiteRunner, OnlyRunsTheSelectedCases) {
  const fs::path dir = scratch("only");
  const fs::path suite = write(dir / "s.toml", small_suite(3));
  const std::string run = std::string(MPMVV_BINARY) + " suite " + suite.string() + " -j 2 -q -o " + (dir / "out").string();
  ASSERT_EQ(shell(run + " --only 'cells=(8|16)$'"), 0);
  std::string manifest = read(dir / "out" / "manifest.json");
  EXPECT_EQ(cases_with_status(manifest, "completed"), 2) << manifest;
  EXPECT_EQ(cases_with_status(manifest, "pending"), 1) << manifest;
  EXPECT_FALSE(fs::exists(dir / "out/cases/square-cells=12.h5"));
  // A case an earlier run left in error, not selected now, does not fail this run.
  write(dir / "out/cases/square-cells=12.json",
        R"({"id": "square-cells=12", "study": "square", "status": "error", "exit_code": 2, "detail": "killed"})");
  EXPECT_EQ(shell(run + " --only 'cells=8$'"), 0);
  ASSERT_EQ(shell(run), 0);
  manifest = read(dir / "out" / "manifest.json");
  EXPECT_EQ(cases_with_status(manifest, "completed"), 3) << manifest;
  EXPECT_EQ(count(manifest, "kept from an earlier run"), 2) << manifest;
  EXPECT_EQ(shell(run + " --only '('"), 2);
  // A selection of nothing is a mistake, not a finished run.
  EXPECT_EQ(shell(run + " --only 'cells=99'"), 2);
  EXPECT_EQ(shell(std::string(MPMVV_BINARY) + " suite " + suite.string() + " --list --only 'cells=99'"), 2);
}

// --threads sets every case's OpenMP threads (two suites sharing the
// machine); without it the cores are shared out over the cases at once.
TEST(SuiteRunner, ThreadsSetsEachCasesThreads) {
  const fs::path dir = scratch("threads");
  const fs::path suite = write(dir / "s.toml", small_suite());
  auto threads_of = [&](const std::string& options, const std::string& out) {
    EXPECT_EQ(shell(std::string(MPMVV_BINARY) + " suite " + suite.string() + " -q --only 'cells=8$' " + options + " -o " +
                    (dir / out).string()),
              0);
    const mpmvv::h5::File file = mpmvv::h5::File::open_read((dir / out / "cases/square-cells=8.h5").string());
    return file.root().attribute_int("threads");
  };
  EXPECT_EQ(threads_of("-j 1 -t 1", "one"), 1);
  EXPECT_EQ(threads_of("-j 1", "all"), std::int64_t(std::max(1u, std::thread::hardware_concurrency())));
  EXPECT_NE(shell(std::string(MPMVV_BINARY) + " suite " + suite.string() + " -q -t 0 -o " + (dir / "zero").string()), 0);
}

// Results written before a key existed are kept when that key is at its
// default now (the behaviour the key was added with) and rerun otherwise; a
// stored key with another value, or one the scene no longer has, is a change.
TEST(SuiteRunner, ResultsOlderThanAKeyAreKeptOnlyAtItsDefault) {
  const fs::path dir = scratch("older");
  const mpmvv::app::Suite s = mpmvv::app::load_suite(write(dir / "s.toml", small_suite()).string());
  const mpmvv::app::SuiteCase& c = s.cases.front();
  auto without = [](const std::string& text, const std::string& key) {
    const auto at = text.find("\n" + key + " = ");
    EXPECT_NE(at, std::string::npos) << key;
    return text.substr(0, at + 1) + text.substr(text.find('\n', at + 1) + 1);
  };
  auto with = [](const std::string& text, const std::string& key, const std::string& value) {
    const auto at = text.find("\n" + key + " = ") + 1;
    const auto end = text.find('\n', at);
    return text.substr(0, at) + key + " = " + value + text.substr(end);
  };
  std::vector<std::string> added;
  EXPECT_TRUE(mpmvv::app::same_configuration(c.configuration, c.configuration, c.defaults, &added));
  EXPECT_TRUE(added.empty());
  // probe_points and dilatation are at their defaults in this case; cells and end_time are not.
  ASSERT_EQ(c.keys.at("probe_points"), 51);
  const std::string older = without(without(c.configuration, "probe_points"), "dilatation");
  EXPECT_TRUE(mpmvv::app::same_configuration(older, c.configuration, c.defaults, &added));
  EXPECT_EQ(added, (std::vector<std::string>{"dilatation", "probe_points"}));
  EXPECT_FALSE(mpmvv::app::same_configuration(without(c.configuration, "cells"), c.configuration, c.defaults));
  EXPECT_FALSE(mpmvv::app::same_configuration(without(c.configuration, "end_time"), c.configuration, c.defaults));
  EXPECT_FALSE(mpmvv::app::same_configuration(older, with(c.configuration, "probe_points", "11"), c.defaults));
  EXPECT_FALSE(mpmvv::app::same_configuration(with(c.configuration, "cfl", "0.25"), c.configuration, c.defaults));
  EXPECT_FALSE(mpmvv::app::same_configuration(c.configuration + "retired_key = 1\n", c.configuration, c.defaults));
  // The same values written otherwise are the same configuration; another
  // value, or a text that is no TOML, is not.
  EXPECT_TRUE(mpmvv::app::same_configuration(with(with(c.configuration, "end_time", "5.0e-3"), "output_times", "[ 0.005 ]"),
                                             c.configuration, c.defaults));
  EXPECT_FALSE(mpmvv::app::same_configuration(with(c.configuration, "end_time", "0.0050000000000001"), c.configuration,
                                              c.defaults));
  EXPECT_FALSE(mpmvv::app::same_configuration(with(c.configuration, "end_time", "= 0.005"), c.configuration, c.defaults));
}

#ifdef MPMVV_HAVE_MPI
// Under mpirun the two ranks share the cases and one manifest lists them all.
TEST(SuiteRunner, MpiRanksShareTheCases) {
  if (shell("command -v mpirun") != 0) GTEST_SKIP() << "mpirun is not installed";
  const fs::path dir = scratch("mpi");
  const fs::path suite = write(dir / "s.toml", small_suite());
  const int status = shell("mpirun --allow-run-as-root --oversubscribe -n 2 " + std::string(MPMVV_BINARY) + " suite " +
                           suite.string() + " -q -o " + (dir / "out").string());
  ASSERT_EQ(status, 0);
  const std::string manifest = read(dir / "out" / "manifest.json");
  EXPECT_EQ(cases_with_status(manifest, "completed"), 3) << manifest;
  EXPECT_TRUE(fs::exists(dir / "out" / "summary.txt"));
}
#endif  // MPMVV_HAVE_MPI

namespace {

// Runs the CI gate's quick suite (with an injected fault, or none) and returns
// the gate's exit status.
int quick_suite_gate(const std::string& fault, const std::string& name) {
  const fs::path dir = scratch(name);
  const std::string environment = fault.empty() ? "" : "MPMVV_FAULT=" + fault + " ";
  const std::string suite = std::string(MPMVV_SOURCE_DIR) + "/suites/ring-quick.toml";
  const int ran = shell(environment + MPMVV_BINARY + " suite " + suite + " -j 2 -q -o " + (dir / "out").string());
  EXPECT_EQ(ran, 0) << "the quick suite itself must run";
  return shell(std::string(MPMVV_BINARY) + " gate " + (dir / "out").string());
}

}  // namespace

// The gate passes on the quick suite and fails when the body force is left out
// or the CPDI gradients carry a 4 % error: it catches real faults.
TEST(Gate, QuickSuitePasses) { EXPECT_EQ(quick_suite_gate("", "gate-healthy"), 0); }
TEST(Gate, FailsWithoutTheBodyForce) { EXPECT_EQ(quick_suite_gate("no-body-force", "gate-no-force"), 1); }
TEST(Gate, FailsWithPerturbedCpdiGradients) { EXPECT_EQ(quick_suite_gate("cpdi-gradient", "gate-gradient"), 1); }

// One suite at a time on a directory: while another process holds DIR/.lock a
// second suite is refused with one line (exit 2) and writes nothing; a
// directory with another suite's manifest is refused unless --force.
TEST(SuiteRunner, ADirectoryInUseOrOfAnotherSuiteIsRefused) {
  const fs::path dir = scratch("lock");
  const fs::path suite = write(dir / "s.toml", small_suite(3));
  const fs::path out = dir / "out";
  fs::create_directories(out);
  const std::string run = std::string(MPMVV_BINARY) + " suite " + suite.string() + " -j 2 -q -o " + out.string();
  {
    const int fd = ::open((out / ".lock").c_str(), O_RDWR | O_CREAT, 0644);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
    const std::string message = dir / "message.txt";
    const int status = std::system((run + " 2> " + message).c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2);
    EXPECT_NE(read(message).find("another mpmvv suite is running in this directory"), std::string::npos)
        << read(message);
    EXPECT_FALSE(fs::exists(out / "manifest.json"));
    ::close(fd);
  }
  ASSERT_EQ(shell(run), 0);
  // The same directory for another suite.
  const fs::path other = write(dir / "other.toml", small_suite(3));
  const std::string run_other =
      std::string(MPMVV_BINARY) + " suite " + other.string() + " -j 2 -q -o " + out.string();
  const std::string message = dir / "other.txt";
  const int status = std::system((run_other + " 2> " + message).c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2);
  EXPECT_NE(read(message).find("holds the results of suite 's'"), std::string::npos) << read(message);
  EXPECT_NE(read(out / "manifest.json").find("\"suite\": \"s\""), std::string::npos);
  ASSERT_EQ(shell(run_other + " --force"), 0);
  EXPECT_NE(read(out / "manifest.json").find("\"suite\": \"other\""), std::string::npos);
}

// A suite killed outright (SIGKILL, which it cannot catch) leaves no case
// running: each case asked the kernel for SIGTERM when its suite ends.
TEST(SuiteRunner, CasesEndWithTheirSuite) {
  const fs::path dir = scratch("orphans");
  const fs::path suite = write(dir / "s.toml", small_suite(30));
  const fs::path out = dir / "out";
  // The pattern's bracket keeps pgrep from finding this shell's own command line.
  // Built from a named string: "'" + a temporary string makes GCC 12 warn
  // falsely (-Wrestrict, inside std::string::insert).
  const std::string hung_case = (out / "cases/[s]quare-cells=16").string();
  const std::string hung = "'" + hung_case + "'";
  const std::string script = "MPMVV_FAULT=hang MPMVV_FAULT_ONLY=cells=16 " + std::string(MPMVV_BINARY) + " suite " +
                             suite.string() + " -j 3 -q -o " + out.string() +
                             " > /dev/null 2>&1 & suite=$!; sleep 2; "
                             "pgrep -f -- " + hung + " > /dev/null && echo started; "
                             "kill -9 $suite; sleep 1; "
                             "pgrep -f -- " + hung + " > /dev/null && echo orphan || echo gone";
  FILE* pipe = ::popen(script.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string said;
  char buffer[256];
  while (std::fgets(buffer, sizeof buffer, pipe)) said += buffer;
  ::pclose(pipe);
  EXPECT_EQ(said, "started\ngone\n");
}

// --list estimates each case before anything runs: in a fresh directory
// from the cheapest case of each study run now (for at most a few seconds),
// with the total and the cases a budget leaves out; once the suite has run,
// each case is done and the budget holds. A suite without a ci tier is
// refused for it.
TEST(SuiteRunner, ListEstimatesEachCaseAndTheBudget) {
  const fs::path dir = scratch("estimate");
  const fs::path suite = write(dir / "s.toml", small_suite());
  const std::string list = std::string(MPMVV_BINARY) + " suite " + suite.string() + " -j 1 -t 1 --list --budget 1e-6 -o " +
                           (dir / "out").string() + " > " + (dir / "list.txt").string() + " 2>&1";
  ASSERT_EQ(std::system(list.c_str()), 0) << read(dir / "list.txt");
  std::string text = read(dir / "list.txt");
  for (const char* id : {"square-cells=8 ", "square-cells=12 ", "square-cells=16 "}) {
    const auto at = text.find(std::string("\n") + id);
    ASSERT_NE(at, std::string::npos) << id << "\n" << text;
    const std::string line = text.substr(at + 1, text.find('\n', at + 1) - at - 1);
    EXPECT_NE(line.find("M particle-steps/s (square-cells=8 run now)"), std::string::npos) << line;
    EXPECT_EQ(line.find(" - "), std::string::npos) << "not estimated: " << line;
  }
  EXPECT_NE(text.find("estimating: running square-cells=8"), std::string::npos) << text;
  EXPECT_NE(text.find("3 cases would not end within it: square-cells=8, square-cells=12, square-cells=16"),
            std::string::npos)
      << text;
  EXPECT_FALSE(fs::exists(dir / "out" / "manifest.json")) << "--list ran the suite";

  ASSERT_EQ(shell(std::string(MPMVV_BINARY) + " suite " + suite.string() + " -j 2 -q -o " + (dir / "out").string()), 0);
  ASSERT_EQ(std::system(list.c_str()), 0) << read(dir / "list.txt");
  text = read(dir / "list.txt");
  EXPECT_EQ(count(text, "done: completed in"), 3) << text;
  EXPECT_EQ(text.find("estimating: running"), std::string::npos) << text;
  EXPECT_NE(text.find("every estimated case ends within it"), std::string::npos) << text;

  const std::string ci = std::string(MPMVV_BINARY) + " suite " + suite.string() + " --tier ci --list > " +
                         (dir / "ci.txt").string() + " 2>&1";
  const int status = std::system(ci.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
  EXPECT_NE(read(dir / "ci.txt").find("no study has a ci tier"), std::string::npos) << read(dir / "ci.txt");
}
