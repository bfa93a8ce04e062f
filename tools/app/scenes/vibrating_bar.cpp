// The axial vibration of a fixed-free bar (PROBLEMS.md section 5), no forcing:
// a strip between roller walls (uniaxial strain, c = sqrt((lambda + 2 mu) /
// rho)), its fixed end on the left wall and its free end short of the right
// one, started in its first mode, v0 = V sin(pi X / 2L). Probes: the line along
// the bar reads the displacement; the free end's history gives the period
// (FFTW) and the amplitude, against omega_1 = pi c / 2L and V / omega_1.
#include <cmath>

#include "analytic/vibrating_bar.hpp"
#include "tools/app/scene/setup.hpp"
#include "vibrating_strip.hpp"

namespace mpmvv::app {

namespace {

std::vector<KeySpec> keys() {
  const double inf = std::numeric_limits<double>::infinity();
  // Steel: one period 4 L / c = 6.71e-4 s for L = 1 m; five periods.
  std::vector<KeySpec> k = solver_keys(32, 0.00336, {0.00084, 0.00168, 0.00252, 0.00336});
  const std::vector<KeySpec> own = {
      {"length", KeyKind::real, 1.0, "L, the length of the bar [m]", 0.0, inf, true},
      {"velocity_amplitude", KeyKind::real, 1.0,
       "V of v0 = V sin(pi X / 2L) [m/s]; the strain amplitude is V / c", 0.0, inf, true},
      {"probe_points", KeyKind::integer, std::int64_t(51), "material points on the probe line", 2, 100000},
  };
  // Steel, E = 207 GPa, nu = 0.3.
  return scene_keys(std::move(k), own, material_keys("linear-elastic", 119.42e9, 79.615e9, 7850.0));
}

SceneSetup setup(const Config& c) {
  SceneSetup s;
  s.material = material_from(c);
  s.geometry = Geometry::plane_strain;
  s.force_free = true;
  const double L = c.real("length");
  const double M = p_wave_modulus(s.material);
  const analytic::VibratingBar bar{L, std::sqrt(M / c.real("density"))};
  const analytic::VibratingBarMotion motion{bar, c.real("velocity_amplitude")};
  s.solution = mms::make_solution(motion, s.material, c.real("density"), s.geometry);

  set_up_vibrating_strip(s, L, int(c.integer("cells")), int(c.integer("probe_points")), bar.period(1),
                         motion.velocity_amplitude / bar.frequency(1));
  return s;
}

}  // namespace

SceneType vibrating_bar_scene() {
  return {"vibrating-bar", "axial vibration of a fixed-free bar, first mode, no forcing (PROBLEMS.md section 5)", keys,
          setup};
}

}  // namespace mpmvv::app
