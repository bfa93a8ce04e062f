// The C interface of the manufactured solutions (mpmvv_mms.h) over the
// scenes' own setups: a solution is the exact solution a scene of that name
// and those settings runs against, with the body force it runs under.
#include "mpmvv_mms.h"

#include <algorithm>
#include <cstddef>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "mms/exact_solution.hpp"
#include "tools/app/mms_command.hpp"

struct mpmvv_mms_solution {
  mpmvv::app::SceneSetup setup;
  std::string name;
  // The force the scene's runs take: the closed form, or the derived one;
  // null for an exact solution without a force. Holds its points.
  std::shared_ptr<mpmvv::mms::ForceField> field;
  mutable std::vector<mpmvv::Vec2> points, forces;  // the last call's
};

namespace {

using mpmvv::Vec2;
using mpmvv::app::KeySpec;
using mpmvv::app::SceneType;

thread_local std::string last_error;

struct Parameter {
  std::string key, default_value, meaning;
};
struct Entry {
  const SceneType* scene;
  bool manufactured;
  std::vector<Parameter> parameters;
};

// Every scene's name, summary and parameters, made once (the texts the
// interface hands out live as long as the library).
const std::vector<Entry>& catalogue() {
  static const std::vector<Entry> entries = [] {
    std::vector<Entry> all;
    for (const SceneType& scene : mpmvv::app::scene_types()) {
      Entry e{&scene, !mpmvv::app::setup_for(scene, {}).force_free, {}};
      for (const KeySpec& k : mpmvv::app::solution_parameters(scene))
        e.parameters.push_back({k.name, mpmvv::app::format_value(k.default_value), k.help});
      all.push_back(std::move(e));
    }
    return all;
  }();
  return entries;
}

const Entry* entry_named(const char* name) {
  if (!name) return nullptr;
  for (const Entry& e : catalogue())
    if (e.scene->name == name) return &e;
  return nullptr;
}

// Every point in the body (and off the axis in r-z), or the first that is not.
bool check_points(const mpmvv_mms_solution* s, std::size_t n, const double* X) {
  if (!s || (n > 0 && !X)) {
    last_error = "no solution or no points";
    return false;
  }
  const bool rz = s->setup.geometry == mpmvv::Geometry::axisymmetric;
  for (std::size_t p = 0; p < n; ++p) {
    const Vec2 x(X[2 * p], X[2 * p + 1]);
    if (!s->setup.contains(x)) {
      last_error = fmt::format("point {} at ({}, {}) lies outside the body of '{}'", p, x.x(), x.y(), s->name);
      return false;
    }
    if (rz && !(x.x() > 0.0)) {
      last_error = fmt::format("point {} at ({}, {}): r-z solutions are evaluated off the axis (R > 0)", p, x.x(),
                               x.y());
      return false;
    }
  }
  last_error.clear();
  return true;
}

void put(double* out, std::size_t p, const Vec2& v) {
  if (out) out[2 * p] = v.x(), out[2 * p + 1] = v.y();
}
void put(double* out, std::size_t p, const mpmvv::Mat2& m) {
  if (out) out[4 * p] = m(0, 0), out[4 * p + 1] = m(0, 1), out[4 * p + 2] = m(1, 0), out[4 * p + 3] = m(1, 1);
}
void put(double* out, std::size_t p, double x) {
  if (out) out[p] = x;
}

}  // namespace

extern "C" {

int mpmvv_mms_count(void) {
  try {
    return int(catalogue().size());
  } catch (const std::exception& e) {
    last_error = e.what();
    return 0;
  }
}

const char* mpmvv_mms_name(int index) {
  if (index < 0 || index >= mpmvv_mms_count()) return nullptr;
  return catalogue()[std::size_t(index)].scene->name.c_str();
}

const char* mpmvv_mms_summary(int index) {
  if (index < 0 || index >= mpmvv_mms_count()) return nullptr;
  return catalogue()[std::size_t(index)].scene->summary.c_str();
}

int mpmvv_mms_manufactured(int index) {
  if (index < 0 || index >= mpmvv_mms_count()) return -1;
  return catalogue()[std::size_t(index)].manufactured ? 1 : 0;
}

int mpmvv_mms_parameter_count(const char* name) {
  const Entry* e = mpmvv_mms_count() > 0 ? entry_named(name) : nullptr;
  return e ? int(e->parameters.size()) : -1;
}

int mpmvv_mms_parameter(const char* name, int index, const char** key, const char** default_value,
                        const char** meaning) {
  const Entry* e = mpmvv_mms_count() > 0 ? entry_named(name) : nullptr;
  const bool found = e && index >= 0 && std::size_t(index) < e->parameters.size();
  const Parameter* q = found ? &e->parameters[std::size_t(index)] : nullptr;
  if (key) *key = q ? q->key.c_str() : nullptr;
  if (default_value) *default_value = q ? q->default_value.c_str() : nullptr;
  if (meaning) *meaning = q ? q->meaning.c_str() : nullptr;
  return found ? 0 : -1;
}

mpmvv_mms_solution* mpmvv_mms_create(const char* name, int count, const char* const* settings) {
  try {
    const SceneType& scene = mpmvv::app::scene_named(name ? name : "");
    std::vector<std::string> overrides;
    for (int k = 0; k < count; ++k) {
      if (!settings || !settings[k]) throw mpmvv::app::ConfigError(fmt::format("setting {} is null", k));
      overrides.emplace_back(settings[k]);
    }
    auto s = std::make_unique<mpmvv_mms_solution>();
    s->setup = mpmvv::app::setup_for(scene, overrides, "setting");
    s->name = scene.name;
    if (!s->setup.force_free)
      s->field = s->setup.fast_body_force ? s->setup.fast_body_force : mpmvv::mms::derived_force_field(s->setup.solution);
    last_error.clear();
    return s.release();
  } catch (const std::exception& e) {
    last_error = e.what();
    return nullptr;
  }
}

void mpmvv_mms_destroy(mpmvv_mms_solution* solution) { delete solution; }

const char* mpmvv_mms_last_error(void) { return last_error.c_str(); }

int mpmvv_mms_axisymmetric(const mpmvv_mms_solution* s) {
  return s && s->setup.geometry == mpmvv::Geometry::axisymmetric ? 1 : 0;
}

double mpmvv_mms_density(const mpmvv_mms_solution* s) { return s ? s->setup.solution->density() : 0.0; }

int mpmvv_mms_contains(const mpmvv_mms_solution* s, double x, double y) {
  return s && s->setup.contains(Vec2(x, y)) ? 1 : 0;
}

int mpmvv_mms_evaluate(const mpmvv_mms_solution* s, double t, std::size_t n, const double* X,
                       mpmvv_mms_fields* out) {
  if (!check_points(s, n, X)) return -1;
  if (!out) return 0;
  const mpmvv::mms::ExactSolution& solution = *s->setup.solution;
#pragma omp parallel for schedule(static)
  for (std::size_t p = 0; p < n; ++p) {
    const mpmvv::mms::ExactFields f = solution.fields(Vec2(X[2 * p], X[2 * p + 1]), t);
    put(out->position, p, f.position);
    put(out->displacement, p, f.displacement);
    put(out->velocity, p, f.velocity);
    put(out->acceleration, p, f.acceleration);
    put(out->F, p, f.deformation_gradient);
    put(out->F33, p, f.hoop_stretch);
    put(out->cauchy_stress, p, f.cauchy_stress);
    put(out->cauchy_stress_33, p, f.cauchy_stress_33);
    put(out->first_piola, p, f.first_piola);
    put(out->body_force, p, s->field ? f.body_force : Vec2::Zero());
  }
  return 0;
}

int mpmvv_mms_body_force(const mpmvv_mms_solution* s, double t, std::size_t n, const double* X, double* b) {
  if (!check_points(s, n, X)) return -1;
  if (!b) return 0;
  if (!s->field) {
    std::fill(b, b + 2 * n, 0.0);
    return 0;
  }
  // The field keeps its points' factors: placed again only for other points.
  const mpmvv_mms_solution& self = *s;
  bool same = self.points.size() == n;
  for (std::size_t p = 0; same && p < n; ++p) same = self.points[p] == Vec2(X[2 * p], X[2 * p + 1]);
  if (!same) {
    self.points.resize(n);
    for (std::size_t p = 0; p < n; ++p) self.points[p] = Vec2(X[2 * p], X[2 * p + 1]);
    self.field->prepare(self.points);
  }
  self.forces.resize(n);
  self.field->evaluate(t, self.forces);
  for (std::size_t p = 0; p < n; ++p) b[2 * p] = self.forces[p].x(), b[2 * p + 1] = self.forces[p].y();
  return 0;
}

}  // extern "C"
