#include "restart_file.hpp"

#include <chrono>
#include <cstdint>
#include <filesystem>

#include <fmt/format.h>

#include "solver/io/hdf5.hpp"

namespace mpmvv::app {

namespace fs = std::filesystem;

void save_restart(const RestartPlan& restart, const LoopState& state, Stepper& stepper, const ScenePersist& scene) {
  const std::string partial = restart.path + ".partial";
  const auto start = std::chrono::steady_clock::now();
  try {
    h5::File file = h5::File::create(partial);
    {
      h5::Group root = file.root();
      for (const auto& [name, value] : restart.identity) root.set_attribute(name, value);
      root.set_attribute("time", state.t);
      root.set_attribute("steps", std::int64_t(state.steps));
      StateArchive a = StateArchive::writing(root.create_group("state"));
      LoopState loop = state;
      a.field("loop", loop);
      a.field("stepper", stepper);
      StateArchive own = a.nested("scene");
      scene(own);
    }
    file.save();
    fs::rename(partial, restart.path);
    if (restart.tell)
      restart.tell(fmt::format("state at t = {:.6g} s (step {}) saved to {}: {:.3g} MB in {:.3g} s", state.t,
                               state.steps, restart.path, double(fs::file_size(restart.path)) / 1e6,
                               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()),
                   false);
  } catch (const std::exception& e) {
    std::error_code ec;
    fs::remove(partial, ec);
    if (restart.tell) restart.tell(fmt::format("saving the state to {} failed: {}", restart.path, e.what()), true);
  }
}

void read_restart(const std::string& path, LoopState& loop, Stepper& stepper, const ScenePersist& scene) {
  try {
    const h5::File file = h5::File::open_read(path);
    const h5::Group root = file.root();
    StateArchive a = StateArchive::reading(root.open_group("state"));
    a.field("loop", loop);
    // The header's time and step (printed when the run goes on) are
    // attributes, outside the datasets' checksums: they must say what the
    // checksummed state says, or a byte of the file changed.
    if (root.attribute_double("time") != loop.t || root.attribute_int("steps") != loop.steps)
      throw std::runtime_error(fmt::format("its header says t = {:.17g} s, step {}, its state t = {:.17g} s, step {}",
                                           root.attribute_double("time"), root.attribute_int("steps"), loop.t,
                                           loop.steps));
    a.field("stepper", stepper);
    StateArchive own = a.nested("scene");
    scene(own);
  } catch (const std::exception& e) {
    throw ConfigError(fmt::format("the restart file {} cannot be read ({}): remove it to start again", path,
                                  e.what()));
  }
}

}  // namespace mpmvv::app
