// The materials of one body: one model for every particle, or a second model
// of the same kind for the particles from `second_from` on (soft against
// stiff, PROBLEMS.md section 6; SceneStages::second_material).
#pragma once

#include <cstddef>
#include <optional>

namespace mpmvv {

template <class Material>
struct Materials {
  Material first;
  std::optional<Material> second;  // absent: one material
  std::size_t second_from = 0;     // the second material's first particle

  // Calls f(material, begin, end) for each material and the particles of the
  // n it holds: all of them, or [0, second_from) and [second_from, n).
  template <class F>
  void for_each(std::size_t n, F&& f) const {
    const std::size_t split = second ? second_from : n;
    f(first, 0, split);
    if (second) f(*second, split, n);
  }
};

}  // namespace mpmvv
