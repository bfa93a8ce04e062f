// What is particular to a scene (SceneSetup): a body in its reference
// configuration, the exact solution that moves it (a manufactured solution
// under its derived body force, or a classical one reached by boundary
// conditions), and the probes where the error is measured; with the keys
// every scene shares. Each scene's file in tools/app/scenes/ fills one in;
// seeding, initial state, probes, norms and health are shared (scene/).
#pragma once

#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mms/exact_solution.hpp"
#include "mms/force_field.hpp"
#include "solver/boundary.hpp"
#include "scene.hpp"
#include "settling.hpp"
#ifdef MPMVV_HAVE_CGAL
#include "body.hpp"
#endif

namespace mpmvv::app {

// What a probe reads off a material point, from its current and reference
// positions (in r-z, x is r and y is z).
enum class ProbeQuantity {
  angular_displacement,  // atan2(x) - atan2(X) [rad]
  radial_displacement,   // |x| - |X| in plane strain, r - R in r-z [m]
  displacement_x,        // x - X [m] (r - R in r-z)
  displacement_y,        // y - Y [m] (z - Z in r-z)
};
const char* to_string(ProbeQuantity q);

struct ProbeLine {
  std::string name;                 // group under /probes
  ProbeQuantity quantity;
  std::string parameter_name;       // what the line is parametrised by, e.g. "reference_radius"
  std::vector<double> parameter;    // its value at each point
  std::vector<Vec2> reference;      // the material points
  std::optional<double> reference_angle;  // lines Theta = const of the plane-strain rings
};

struct ProbePoint {
  std::string name;                 // recorded after every step
  ProbeQuantity quantity;
  Vec2 reference;
};

// Material points equally spaced around a circle about the origin; the
// amplitude spectrum of the error around it (FFTW) measures lost axisymmetry.
struct ProbeCircle {
  ProbeQuantity quantity;
  double radius;
  int points;
};

using Measurements = std::vector<std::pair<std::string, double>>;

// What a scene's measurements read at the end of a run.
struct RunRecord {
  const std::vector<double>& point_time;                 // after every step
  const std::vector<std::vector<double>>& point_values;  // per probe point, at those times
  const Stepper& stepper;
};

// Everything particular to one scene: a manufactured solution under its
// derived force, or a classical exact solution reached by boundary conditions.
struct SceneSetup {
  std::shared_ptr<const mms::ExactSolution> solution;
  MaterialModel material;
  // A second material in the same body (soft against stiff): the particles
  // whose reference position `in_second_material` holds take it, and are
  // seeded after the others (SceneStages::second_material). Absent: one.
  std::optional<MaterialModel> second_material;
  std::function<bool(const Vec2&)> in_second_material;
  Geometry geometry = Geometry::plane_strain;
  GridGeometry grid;
  std::function<bool(const Vec2&)> contains;  // the body, in reference coordinates
#ifdef MPMVV_HAVE_CGAL
  std::optional<Body> body;                    // the same body, exactly (seeding = "exact")
#endif
  // A body described once: `contains` for every build and, with CGAL, the
  // exact `body`, the same region.
  void body_is_rectangle(const Vec2& lower, const Vec2& upper);
  void body_is_annulus(double inner_radius, double outer_radius);  // about the origin
  std::vector<ProbeLine> lines;
  std::vector<ProbePoint> points;
  std::optional<ProbeCircle> circle;
  // A classical exact solution that needs no force: the body-force stage is
  // left out (the exact motion still gives the initial state and the errors).
  bool force_free = false;
  // Boundary conditions and loads (solver/boundary.hpp), built once the
  // particles are seeded (a traction names its particles); absent for the
  // manufactured problems. `loading` says what they are, for the results file.
  std::function<SceneStages(const Particles&, const GridGeometry&)> stages;
  std::string loading;
  // Error columns of the scene's own, computed at every output time from
  // the run so far (the stepper's state, the probe points' histories), after
  // the probe and particle norms.
  std::vector<std::string> extra_error_names;
  std::function<std::vector<double>(double t, const RunRecord&)> extra_errors;
  // Scalars measured at the end of a run (name, value), e.g. a period from the
  // first probe point's history, or the mean strain of the bar's middle.
  std::function<Measurements(const RunRecord&)> measure;
  // False when the scene's exact solution is not a motion of the body (Hertz
  // contact): the particle displacement norms are left out of /errors.
  bool exact_motion = true;
  // Scalars recorded after every step (e.g. load and approach), written under
  // /probes/history with the time.
  std::vector<std::string> history_names;
  std::function<std::vector<double>(double t, const Stepper&)> history;
  // Writes what the scene gathered itself under /probes (e.g. pressure profiles).
  std::function<void(h5::Group& probes)> write_extra;
  // The motion is analytic in time before this (a load ramp is constant after
  // it): `mms check` draws its times below it. Infinite: everywhere.
  double smooth_until = std::numeric_limits<double>::infinity();
  // A closed form that equals the derived force (tests/test_manufactured.cpp
  // shows it), used instead of automatic differentiation for speed; absent
  // otherwise.
  std::shared_ptr<mms::ForceField> fast_body_force;
  // Why a run of this setup would not verify anything, and the key to blame
  // (a manufactured motion its boundary conditions cannot hold): a run or a
  // suite refuses it with that message, while `mms eval`, `mms check` and the
  // library still evaluate the solution. Absent: it runs.
  struct Refusal {
    std::string key, why;
  };
  std::optional<Refusal> run_refused;
  // A scene that settles to a static state (scenes/quasi_static.hpp): what
  // the results file's measurements settling_displacement and settling_strain,
  // how far its end still is from that state, are measured from (settling.hpp).
  // Absent: a dynamic scene.
  std::optional<SettlingBody> settling;
};

// The seeding key every scene accepts: "exact" (clipped
// volumes, CGAL) by default when built with CGAL, else "centre".
KeySpec seeding_key();
// The key of every scene with a manufactured body force: where a particle
// samples it (mms/force_field.hpp), "centroid" by default.
KeySpec force_quadrature_key();

// The key of a problem whose body force has a closed form beside the derived
// one (`closed_form` says which): "closed-form" by default, for the
// neo-Hookean solid only.
KeySpec body_force_key(const std::string& closed_form);
// The neo-Hookean solid the closed form is written for when it is asked for,
// else null; rejects it for another material, naming where the material came
// from (throws ConfigError).
const NeoHookean* closed_form_force(const Config& config, const MaterialModel& material, const std::string& closed_form);

// A scene's keys: the solver's, its own, the seeding key and the material's.
std::vector<KeySpec> scene_keys(std::vector<KeySpec> solver, const std::vector<KeySpec>& own,
                                  const std::vector<KeySpec>& material);

// Material keys every scene accepts, with its defaults.
std::vector<KeySpec> material_keys(const std::string& default_material, double lambda, double mu, double density);
MaterialModel material_from(const Config& config);

// Refuses a square grid of `cells` cells over the square `domain` [m] that
// leaves less than two cells between a body reaching radius `reach` [m] and
// the walls (a ring's; `what` names it), with the smallest count of cells
// and the domain that would fit. Blames the domain where no count of cells
// can fit or where the domain alone was set, else cells (throws ConfigError).
void require_two_cells_clearance(const Config& config, const std::string& what, double reach, double domain,
                                 int cells);

// A line of `count` equally spaced points from a to b.
std::vector<Vec2> points_on_segment(const Vec2& a, const Vec2& b, int count);

}  // namespace mpmvv::app
