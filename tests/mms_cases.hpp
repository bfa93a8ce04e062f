// What the manufactured-solution tests share (test_jet.cpp,
// test_manufactured.cpp, test_closed_forms.cpp): the names they use, the
// problem configurations every derived force is checked on, random material
// points of a body, and the tolerance of the lanes' derived force.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <ostream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "mms/exact_solution.hpp"
#include "mms/jet.hpp"
#include "mms/manufactured.hpp"
#include "mms/residual_check.hpp"
#include "mms/ring.hpp"
#include "tools/app/scene/setup.hpp"

namespace mpmvv::testing::mms_cases {

using mpmvv::Geometry;
using mpmvv::Mat2;
using mpmvv::NeoHookean;
using mpmvv::Particles;
using mpmvv::Vec2;
using mpmvv::app::Config;
using mpmvv::app::SceneSetup;
using mpmvv::mms::ExactFields;
using mpmvv::mms::ExactSolution;
using mpmvv::mms::Jet;
using mpmvv::mms::Manufactured;
using mpmvv::mms::ResidualCheck;
using mpmvv::mms::RingMms;
using mpmvv::mms::RingMotion;
using mpmvv::mms::RingParameters;
using mpmvv::mms::RingTimeFunction;
using std::numbers::pi;


// The lanes' derived force against the scalar jets', relative to the largest
// force at the time: their sin, cos and ln differ by about one unit in the
// last place (solver/lane_math.hpp), and the force is formed from them by
// sums of terms up to tens of times the force itself (the stiff problems'
// stress divergence against the inertia it drives). Measured at most 1.9e-15
// (the Mooney-Rivlin ring and the ring at A = 1).
inline constexpr double kLaneForceTolerance = 1e-14;

// |a - b| relative to |b|, or absolute where |b| < 1 (derivatives that pass
// through zero at a sample point).
inline double relative_difference(double a, double b) { return std::abs(a - b) / std::max(std::abs(b), 1.0); }

// One problem configuration: the problem's defaults plus overrides.
struct ProblemCase {
  const char* label;
  const char* problem;
  std::vector<std::string> overrides;
};

inline void PrintTo(const ProblemCase& c, std::ostream* out) { *out << c.label; }

inline const ProblemCase kProblemCases[] = {
    {"ring_cosine_A0p5", "ring", {"time_function=cosine", "amplitude=0.5"}},
    {"ring_cosine_A1", "ring", {"time_function=cosine", "amplitude=1"}},
    {"ring_sine_A0p5", "ring", {"time_function=sine", "amplitude=0.5"}},
    {"ring_sine_A1", "ring", {"time_function=sine", "amplitude=1"}},
    {"ring_mooney_rivlin", "ring", {"material=mooney-rivlin", "c2=50", "body_force=derived"}},
    {"ring_linear_elastic", "ring", {"material=linear-elastic", "body_force=derived"}},
    {"axis_aligned_2d", "axis-aligned", {}},
    {"axis_aligned_1d", "axis-aligned", {"variant=1d"}},
    {"expanding_ring", "expanding-ring", {}},
    {"rz_cylinder_hollow", "rz-cylinder", {}},
    {"rz_cylinder_solid", "rz-cylinder", {"inner_radius=0"}},
};

inline Config config_for(const ProblemCase& c) {
  const mpmvv::app::SceneType* problem = mpmvv::app::find_scene_type(c.problem);
  if (!problem) throw std::runtime_error(std::string("no problem ") + c.problem);
  Config config(problem->name, problem->keys());
  for (const std::string& o : c.overrides) config.set_from_text(o);
  return config;
}

inline SceneSetup setup_for(const ProblemCase& c) {
  return mpmvv::app::find_scene_type(c.problem)->setup(config_for(c));
}

struct Sample {
  Vec2 X;
  double t;
};

// `count` random material points of the body, each at least 0.01 h inside it
// along both axes (the finite differences of check() reach 3e-3 of the
// motion's length scale) and, in r-z, at R > 0.02 R_o, with times in
// [0, end_time]; rejection sampling in the walled box from a fixed seed.
inline std::vector<Sample> body_samples(const SceneSetup& s, const Config& c, std::size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  const Vec2 lo = s.grid.wall_lower(), hi = s.grid.wall_upper();
  std::uniform_real_distribution<double> ux(lo.x(), hi.x()), uy(lo.y(), hi.y()), ut(0.0, c.real("end_time"));
  const double margin = 0.01 * s.grid.h;
  std::vector<Sample> out;
  while (out.size() < count) {
    const Vec2 X(ux(rng), uy(rng));
    bool inside = s.contains(X);
    for (const Vec2& d : {Vec2(margin, 0), Vec2(-margin, 0), Vec2(0, margin), Vec2(0, -margin)})
      inside = inside && s.contains(X + d);
    if (s.geometry == Geometry::axisymmetric && !(X.x() > 0.02 * c.real("outer_radius"))) inside = false;
    if (inside) out.push_back({X, ut(rng)});
  }
  return out;
}

// The largest residual |a - Div P / rho_0 - b| over the points divided by the
// largest scale |a| + |Div P / rho_0| + |b| over them: `mpmvv mms check`.
inline double largest_relative_residual(const ExactSolution& s, const std::vector<Sample>& points) {
  double scale = 0.0, worst = 0.0;
  for (const Sample& p : points) {
    const ResidualCheck c = s.check(p.X, p.t);
    scale = std::max(scale, c.scale);
    worst = std::max(worst, c.residual.norm());
  }
  return worst / scale;
}


// Random points of the default ring 0.75 < R < 1.25 and times in [0, 1].
inline std::vector<Sample> ring_samples(std::size_t count, unsigned seed, double inner = 0.75, double outer = 1.25) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> radius(inner, outer), angle(-pi, pi), time(0.0, 1.0);
  std::vector<Sample> out;
  for (std::size_t k = 0; k < count; ++k) {
    const double R = radius(rng), Theta = angle(rng);
    out.push_back({Vec2(R * std::cos(Theta), R * std::sin(Theta)), time(rng)});
  }
  return out;
}

}  // namespace mpmvv::testing::mms_cases
