// Soft against stiff (PROBLEMS.md section 6): the fixed-free bar of the
// vibrating-bar scene made of two bonded layers, the first (from the fixed
// end to `interface` L) of the scene's material, the second of the same model
// with every constant times `stiffness_ratio`, both of the same density. The
// explicit step follows the stiffer layer's waves while the softer one sets
// the period, so a small ratio costs steps (about 1 / sqrt(ratio) more per
// period) and tests the interface, where the strain jumps by 1 / ratio.
// Started in the first mode of analytic/layered_bar.hpp, v0 = V phi(X), V set
// by the mode's largest strain; the free end's history gives the period and
// the amplitude.
#include <cmath>
#include <memory>
#include <numbers>

#include "analytic/layered_bar.hpp"
#include "tools/app/scene/setup.hpp"
#include "vibrating_strip.hpp"

namespace mpmvv::app {

namespace {

std::vector<KeySpec> keys() {
  const double inf = std::numeric_limits<double>::infinity();
  // Steel against a layer 100 times softer: one period 3.4e-3 s for L = 1 m
  // (the steel bar alone: 6.7e-4 s); five periods. A suite that sweeps the
  // ratio sets the end time with it (suites/layered-bar.toml).
  std::vector<KeySpec> k = solver_keys(32, 0.017, {0.0034, 0.0068, 0.0102, 0.0136, 0.017});
  const std::vector<KeySpec> own = {
      {"length", KeyKind::real, 1.0, "L, the length of the bar [m]", 0.0, inf, true},
      {"interface", KeyKind::real, 0.5,
       "where the second layer starts, as a fraction of L (0.5: halves; a multiple of 1 / cells puts it on a cell "
       "line)", 0.0, 1.0, true, true},
      {"stiffness_ratio", KeyKind::real, 0.01,
       "every constant of the second layer's material over the first's (same density): below 1 a softer free end",
       0.0, inf, true},
      {"strain_amplitude", KeyKind::real, 1e-3,
       "the mode's largest strain |u_X| (in the softer layer when the ratio is below 1): v0 = V phi(X) with V "
       "set to give it", 0.0, 0.1, true},
      {"probe_points", KeyKind::integer, std::int64_t(51), "material points on the probe line", 2, 100000},
  };
  // Steel, E = 207 GPa, nu = 0.3.
  return scene_keys(std::move(k), own, material_keys("linear-elastic", 119.42e9, 79.615e9, 7850.0));
}

// The material with every constant times `factor`: the same model, stiffer or softer.
MaterialModel scaled(const MaterialModel& material, double factor) {
  struct Scale {
    double f;
    MaterialModel operator()(const NeoHookean& m) const { return NeoHookean{f * m.lambda, f * m.mu}; }
    MaterialModel operator()(const LinearElastic& m) const { return LinearElastic{f * m.lambda, f * m.mu}; }
    MaterialModel operator()(const MooneyRivlin& m) const { return MooneyRivlin{f * m.c1, f * m.c2, f * m.bulk_modulus}; }
  };
  return std::visit(Scale{factor}, material);
}

// The exact fields of each layer from its own material: stress and the
// derived force of the one motion, with the constants of the layer that
// holds X.
class LayeredSolution final : public mms::ExactSolution {
 public:
  LayeredSolution(std::shared_ptr<const mms::ExactSolution> first, std::shared_ptr<const mms::ExactSolution> second,
                  double interface, double length)
      : first_(std::move(first)), second_(std::move(second)), interface_(interface), length_(length) {}
  Geometry geometry() const override { return first_->geometry(); }
  double density() const override { return first_->density(); }
  Vec2 position(const Vec2& X, double t) const override { return first_->position(X, t); }
  mms::ExactFields fields(const Vec2& X, double t) const override { return of(X).fields(X, t); }
  mms::ExactFields state(const Vec2& X, double t) const override { return of(X).state(X, t); }
  Vec2 body_force(const Vec2& X, double t) const override { return of(X).body_force(X, t); }
  void body_forces(double t, const std::vector<Vec2>& X, std::vector<Vec2>& b) const override {
    for (std::size_t p = 0; p < X.size(); ++p) b[p] = body_force(X[p], t);
  }
  // The motion is smooth within each layer only (the strain jumps at the
  // interface), so the check's differences (mms/residual_check.hpp: 3 steps of
  // a thousandth of the length each way for P, of F within each) stay within one layer: a point
  // closer to the interface is checked at the nearest point that is not.
  mms::ResidualCheck check(const Vec2& X, double t, double step = mms::kCheckStep) const override {
    const double reach = 6.5 * step * length_;
    Vec2 at = X;
    if (std::abs(X.x() - interface_) < reach) at.x() = interface_ + (X.x() < interface_ ? -reach : reach);
    return of(at).check(at, t, step);
  }

 private:
  const mms::ExactSolution& of(const Vec2& X) const { return X.x() < interface_ ? *first_ : *second_; }
  std::shared_ptr<const mms::ExactSolution> first_, second_;
  double interface_, length_;
};

SceneSetup setup(const Config& c) {
  SceneSetup s;
  s.material = material_from(c);
  s.second_material = scaled(s.material, c.real("stiffness_ratio"));
  s.geometry = Geometry::plane_strain;
  s.force_free = true;
  const double L = c.real("length");
  const double L1 = c.real("interface") * L;
  const double density = c.real("density");
  s.in_second_material = [L1](const Vec2& X) { return X.x() >= L1; };
  const analytic::LayeredBar bar{L1, L - L1, p_wave_modulus(s.material), p_wave_modulus(*s.second_material),
                                 density, density};
  const double omega = bar.first_frequency();
  // The mode's largest slope: k1 at the fixed end, or |B| k2 sin(k2 L2) at the
  // interface (|phi'| = |B| k2 sin(k2 (L - X)) grows towards it, k2 L2 < pi / 2).
  const double k1 = omega / bar.wave_speed_1(), k2 = omega / bar.wave_speed_2();
  const double slope = std::max(k1, std::abs(bar.second_amplitude(omega)) * k2 * std::sin(k2 * (L - L1)));
  const analytic::LayeredBarMotion motion{bar, omega, c.real("strain_amplitude") * omega / slope};
  s.solution = std::make_shared<LayeredSolution>(mms::make_solution(motion, s.material, density, s.geometry),
                                                 mms::make_solution(motion, *s.second_material, density, s.geometry),
                                                 L1, L);
  set_up_vibrating_strip(s, L, int(c.integer("cells")), int(c.integer("probe_points")), 2.0 * std::numbers::pi / omega,
                         motion.velocity_amplitude / omega * std::abs(motion.mode(L)));
  return s;
}

}  // namespace

SceneType layered_bar_scene() {
  return {"layered-bar",
          "axial vibration of a fixed-free bar of a stiff and a soft layer, first mode, no forcing (PROBLEMS.md "
          "section 6: stiffness contrast)",
          keys, setup};
}

}  // namespace mpmvv::app
