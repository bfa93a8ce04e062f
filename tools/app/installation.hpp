// Where mpmvv finds what it ships beside the binary: the reports package and
// the scene and suite files. Installed (cmake --install), they are under
// <prefix>/share/mpmvv/, found relative to the binary, so an installed tree
// works from wherever it is copied and with the source tree removed; a binary
// of the build tree reads them from the source tree it was built from.
#pragma once

#include <filesystem>
#include <string>

namespace mpmvv::app {

// The running binary's path (/proc/self/exe); throws std::runtime_error.
std::string self_executable();

struct Installation {
  std::filesystem::path reports;  // the reports package (a folder named reports, with __init__.py)
  std::filesystem::path suites;   // the shipped suites, their scene files in suites/scenes/
  bool installed = false;         // found under the binary's prefix, not in the source tree
};

// The installed copy when the binary's prefix holds one, else the source tree's.
Installation installation();

}  // namespace mpmvv::app
