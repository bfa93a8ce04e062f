// Every scene mpmvv runs, each one line of the list below: the function of
// its file in tools/app/scenes/ that describes it (README: "Adding a scene").
#include "tools/app/scene/setup.hpp"

// SCENE(function) for each scene; NEEDS_SUNDIALS(function) for a scene whose
// exact state is a root KINSOL finds (a build without SUNDIALS leaves it out).
#define MPMVV_SCENES(SCENE, NEEDS_SUNDIALS) \
  SCENE(ring_scene)                         \
  SCENE(axis_aligned_scene)                 \
  SCENE(expanding_ring_scene)               \
  SCENE(rz_cylinder_scene)                  \
  SCENE(vibrating_bar_scene)                \
  SCENE(uniaxial_tension_scene)             \
  SCENE(uniaxial_compression_scene)         \
  SCENE(shear_scene)                        \
  SCENE(hertz_cylinder_scene)               \
  SCENE(hertz_sphere_scene)                 \
  SCENE(user_motion_scene)                  \
  NEEDS_SUNDIALS(neo_hookean_bar_scene)     \
  NEEDS_SUNDIALS(layered_bar_scene)

namespace mpmvv::app {

#define MPMVV_DECLARE(function) SceneType function();
#ifdef MPMVV_HAVE_SUNDIALS
#define MPMVV_WITH_SUNDIALS(function) function(),
MPMVV_SCENES(MPMVV_DECLARE, MPMVV_DECLARE)
#else
#define MPMVV_WITH_SUNDIALS(function)
MPMVV_SCENES(MPMVV_DECLARE, MPMVV_WITH_SUNDIALS)
#endif
#define MPMVV_ENTRY(function) function(),

const std::vector<SceneType>& scene_types() {
  static const std::vector<SceneType> scenes = {MPMVV_SCENES(MPMVV_ENTRY, MPMVV_WITH_SUNDIALS)};
  return scenes;
}

const SceneType* find_scene_type(const std::string& name) {
  for (const SceneType& s : scene_types())
    if (s.name == name) return &s;
  return nullptr;
}

}  // namespace mpmvv::app
