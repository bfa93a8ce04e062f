#include "installation.hpp"

#include <stdexcept>
#include <system_error>

namespace mpmvv::app {

namespace fs = std::filesystem;

std::string self_executable() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot find the mpmvv executable (/proc/self/exe): " + ec.message());
  return p.string();
}

Installation installation() {
  // MPMVV_DATA_FROM_BIN: the install's data folder relative to its bin folder
  // (share/mpmvv from bin: ../share/mpmvv), set by CMake from GNUInstallDirs.
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path data = (exe.parent_path() / MPMVV_DATA_FROM_BIN).lexically_normal();
    if (fs::exists(data / "python" / "reports" / "__init__.py", ec))
      return {data / "python" / "reports", data / "suites", true};
  }
  return {fs::path(MPMVV_SOURCE_ROOT) / "reports", fs::path(MPMVV_SOURCE_ROOT) / "suites", false};
}

}  // namespace mpmvv::app
