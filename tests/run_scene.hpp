// Tests that run the mpmvv binary on a shipped scene and read its results
// file. Needs MPMVV_BINARY and MPMVV_SOURCE_DIR (tests/CMakeLists.txt).
#pragma once

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "solver/io/hdf5.hpp"

namespace mpmvv::testing {

// Runs `mpmvv run suites/scenes/<scene> -q -t THREADS <arguments>` into a
// scratch results file named `name`, expects its exit status (0: completed;
// 1: failed or lost) and opens the file.
inline h5::File run_scene(const std::string& scene, const std::string& name, const std::string& arguments,
                          int expected_exit = 0, int threads = 1) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "mpmvv-scene-runs";
  std::filesystem::create_directories(dir);
  const std::filesystem::path out = dir / (name + ".h5");
  std::filesystem::remove(out);
  const std::string command = std::string(MPMVV_BINARY) + " run " + MPMVV_SOURCE_DIR + "/suites/scenes/" + scene +
                              " -q -t " + std::to_string(threads) + " " + arguments + " -o " + out.string() + " > /dev/null 2>&1";
  const int status = std::system(command.c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == expected_exit) << command;
  return h5::File::open_read(out.string());
}

// A monitor's column (/probes/monitors/<name>) at the output times.
inline std::vector<double> monitor(const h5::File& f, const std::string& name) {
  return f.root().open_group("probes").open_group("monitors").read_doubles(name);
}

}  // namespace mpmvv::testing
