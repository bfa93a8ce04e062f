// What every stepper of the time loop is (time_loop.hpp): the explicit MPM
// step (explicit_stepper.hpp) and the implicit quasi-static one
// (implicit/static_stepper.hpp) alike. It owns the model and the grid fields,
// steps, scans the particles for the stable step and for faults, and keeps
// the run's ledgers.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "boundary.hpp"
#include "domain_polygons.hpp"
#include "model.hpp"
#include "monitors.hpp"
#include "stage_times.hpp"

namespace mpmvv {

class StateArchive;  // io/state_archive.hpp

// Why a particle stops the run.
struct ParticleFault {
  std::string reason;  // "nan", "non-positive J", "outside grid", "domain too wide" (exact CPDI)
  std::string detail;  // values that show it
};

// How far a body settling to a static state still is from it: the RMS over
// the body of the displacement still to come [m], and of the small strain
// that motion makes (the symmetric part of F's change; dimensionless).
struct Settling {
  double displacement = std::numeric_limits<double>::quiet_NaN();
  double strain = std::numeric_limits<double>::quiet_NaN();
};

class Stepper {
 public:
  virtual ~Stepper() = default;

  // Advances every particle (and tracer) from t to t + dt. Velocities change by
  // `kick` times the acceleration at t (eq. 1.72): kick = dt for the update as
  // written, or the central-difference kick (see TimeIntegration).
  virtual void step(double t, double dt, double kick) = 0;
  // Largest signal speed and the first particle whose state stops the run.
  virtual ParticleScan scan() const = 0;
  // The same scan, made while the step that starts at t does its first stage,
  // which weighs the same state (an explicit step's map: no stage of the
  // step needs dt before it). The next step(t, ...) then starts after that
  // stage. A stepper without such a stage only scans.
  virtual ParticleScan prepare_step(double /*t*/) { return scan(); }
  virtual ParticleFault diagnose(std::size_t particle) const = 0;

  const Model& model() const { return model_; }
  Model& model() { return model_; }
  const GridFields& grid_fields() const { return fields_; }
  // Wall time spent evaluating the body force, apart from the solver's own.
  double forcing_seconds() const { return forcing_seconds_; }
  // Wall time per stage of the step so far (stage_times.hpp); zero for a
  // stepper whose stages are not timed.
  const StageTimes& stage_times() const { return stage_times_; }
  // The bytes the particles' arrays, the stepper's own arrays and its body
  // force's hold now, over the particle count.
  virtual double bytes_per_particle() const {
    return model_.particles.size() ? double(model_.particles.bytes()) / double(model_.particles.size()) : 0.0;
  }
  // Per node constraint of the scene, its reaction in the last step
  // (apply_constraints); empty without constraints.
  const std::vector<double>& constraint_reactions() const { return reactions_; }
  // With a contact master, the contact force of the last step at each node;
  // empty without one.
  const ContactForces& contact_forces() const { return contact_forces_; }
  // Why the last step could not be taken (an implicit solve that did not
  // converge); empty when it was.
  virtual std::string step_failure() const { return {}; }
  // Counters of the stepper's own (Newton and Krylov iterations), for the results file.
  virtual std::vector<std::pair<std::string, double>> statistics() const { return {}; }
  // For a scene that settles to a static state by load steps that each end in
  // equilibrium (the implicit step): how far the last one still is from it
  // (Settling), from the body's small-strain shear modulus; NaN for a stepper
  // that settles by relaxing in time (the scene measures that itself).
  virtual Settling distance_to_equilibrium(double /*shear_modulus*/) const { return {}; }
  // The run's health now (monitors.hpp), and the work done on it so far.
  virtual Monitors monitors() const = 0;
  // The current domain of every particle (domain_polygons.hpp); empty for a
  // method without domains, and from a stepper that does not give them (the
  // implicit one).
  virtual DomainPolygons domain_polygons() const { return {}; }
  // The largest frequency omega_max [rad/s] of the grid's motion linearized
  // about the current state, by power iteration (explicit steppers; NaN
  // otherwise). Central differences are stable while dt <= 2 / omega_max.
  virtual double largest_frequency(int /*iterations*/) const { return std::numeric_limits<double>::quiet_NaN(); }
  const EnergyLedger& ledger() const { return ledger_; }
  // Whether persist() holds all that a step hands to the next, so that a run
  // continued from a restart file ends with the bits of a run that never
  // stopped (the explicit steppers; not the implicit one, whose solver keeps
  // its own).
  virtual bool restartable() const { return false; }
  // Writes or reads (io/state_archive.hpp) the state between two steps: the
  // particles, the tracers, the work done on them and the time spent so far.
  // Read into a stepper built from the same configuration, it continues the
  // run: the next prepare_step(t) maps afresh.
  virtual void persist(StateArchive& archive);

 protected:
  explicit Stepper(Model model) : model_(std::move(model)) { fields_.resize(model_.grid.node_count()); }
  Model model_;
  GridFields fields_;
  double forcing_seconds_ = 0.0;
  mutable StageTimes stage_times_;  // mutable: scan() is const
  std::vector<double> reactions_;
  ContactForces contact_forces_;
  EnergyLedger ledger_;
};

}  // namespace mpmvv
