#pragma once
// Explicit central-difference time integration (velocity Verlet form, so velocities are known at full
// steps for the energy balance) of the SPG tissue with boundary conditions and body loads:
//   v(n+1/2) = v(n) + dt/2 a(n);  constraints;  x(n+1) = x(n) + dt v(n+1/2);
//   forces at x(n+1);  v(n+1) = v(n+1/2) + dt/2 a(n+1);  constraints.
// Fixed particles (ParticleFlag) have v = 0, symmetry particles v_z = 0 (opened ones z >= 0: a step's
// drift stops on the plane, symmetry_slit.h); velocity constraints prescribe
// one component on a set of particles. Energy balance: kinetic - kinetic(0) = work of the model's forces
// + work of body loads + work of the reactions (on constrained components: m dv/dt - f, times the
// displacement); its relative error is the drift of the integrator.
#include <Eigen/Dense>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <utility>
#include <array>
#include <vector>

#include "solver/tissue/spg_tissue.h"
#include "solver/tissue/tissue_mass_scaling.h"
#include "solver/tissue/tissue_rate_levels.h"

namespace needle {

struct VelocityConstraint {
  std::vector<std::int32_t> particles;
  int axis = 0;                                              // 0 x, 1 y, 2 z
  std::function<double(double time_ms)> velocity_mm_per_ms;  // prescribed velocity component
  std::vector<double> scale;  // optional, one per particle: its velocity is scale x the function
};

struct EnergyBalance {
  double kinetic_mJ = 0;
  double model_work_mJ = 0;        // work of internal and stabilization forces (= - stored and dissipated energy)
  double body_work_mJ = 0;
  double external_work_mJ = 0;     // work of external forces (contact with the needle)
  double constraint_work_mJ = 0;
  double initial_kinetic_mJ = 0;
  double mass_scaling_mJ = 0;      // kinetic energy the mass scaling's mass changes added (tissue_mass_scaling.h)
  // |KE - KE0 - W_model - W_body - W_external - W_constraint - E_mass_scaling| / max(|terms|): the integrator's drift
  double relative_error() const;
};

struct StepReport {
  double dt_ms = 0;
  std::int64_t bonds_broken_now = 0;
  std::int64_t rate_factor_capped = 0;
  std::int64_t particles_detached_now = 0;
};

class TissueDynamics {
 public:
  TissueDynamics(SpgTissue& tissue, std::vector<VelocityConstraint> constraints,
                 const Eigen::Vector3d& body_acceleration_mm_per_ms2 = Eigen::Vector3d::Zero());

  // External forces (the contact), one per particle, at the current state: they join the accelerations
  // that start the next step (call before the first step; finish_step takes each step's end values). They
  // act like internal forces in the step, and their work is booked apart.
  void set_external_forces(const std::vector<Vec3d>& force_N);

  // Selective mass scaling to this step (tissue_mass_scaling.h), before the first step; 0: none.
  void set_mass_scaling(double target_dt_ms);
  const TissueMassScaling* mass_scaling() const { return mass_scaling_.get(); }
  // A new target for the mass scaling there is, between steps (a multi-rate cycle under way keeps its base step).
  void retarget_mass_scaling(double target_dt_ms);
  // Multi-rate stepping (tissue_rate_levels.h) with this many levels above the base step, before the first step;
  // 0: one rate. The forces and force_N are then impulse-weighted (spg_tissue.h).
  void set_rate_levels(int max_level, double safety = 1.0);
  const TissueRateLevels* rate_levels() const { return rate_levels_.get(); }
  // Whether the next step starts a cycle of the rate levels (the fast particles given before it count for it).
  bool at_rate_cycle_start() const { return rate_levels_ && !drifted_ && tissue_.rate_cycle_complete(); }
  void set_fast_particles(std::vector<std::uint8_t> fast);

  // The step the next step will take: the tissue's stable step (with mass scaling at least its target)
  // capped at max_dt_ms.
  double time_step_ms(double max_dt_ms = std::numeric_limits<double>::infinity()) const;
  // One step in two halves, so that another body can move between them (the coupled insertion):
  //   kick_and_drift: v(n+1/2) = v(n) + dt/2 a(n), constraints, x(n+1) = x(n) + dt v(n+1/2), t += dt;
  //     dt is the tissue's stable step capped at max_dt_ms (> 0); returns it. With mass scaling the
  //     masses are first set for dt (momentum kept). SolverError on a collapsed time step (below 1e-4 of
  //     the first, unscaled).
  //   finish_step: forces at x(n+1) with the external forces given (nullptr: the last ones, unchanged),
  //     the work of each force, v(n+1) = v(n+1/2) + dt/2 a(n+1), constraints and their work. SolverError
  //     on non-finite forces or energy.
  double kick_and_drift(double max_dt_ms = std::numeric_limits<double>::infinity());
  StepReport finish_step(const std::vector<Vec3d>* external_force_N = nullptr);
  // Between the two halves, a kinematic contact's impulses (particle, J in g mm/ms): each particle's mid-step
  // velocity changes by J/m and its end position, through the drift, by dt J/m. Components the particle's
  // constraints hold (fixed, symmetry) are dropped from J, in place, so what is returned acted. Returns their
  // work, J . (v_before + v_after) / 2 (the exact change of kinetic energy), booked as external work; the
  // step's first-half forces are then booked through the drift before the impulse (velocity Verlet's account).
  double apply_impulses(std::vector<std::pair<std::int32_t, Vec3d>>& impulse_g_mm_per_ms);
  // Both halves with the external forces held.
  StepReport step(double max_dt_ms = std::numeric_limits<double>::infinity());

  double time_ms() const { return time_ms_; }
  std::int64_t steps() const { return steps_; }
  const EnergyBalance& energy() const { return energy_; }
  const TissueParticles& particles() const { return tissue_.particles(); }
  const std::vector<Vec3d>& external_forces() const { return external_force_; }
  // Sum over a constraint's particles of the force the tissue exerts on them (N): minus the reaction.
  Eigen::Vector3d constraint_internal_force_N(size_t constraint) const;

 private:
  // drift_dt_ms > 0 before a drift of that length: an open symmetry particle's v_z is then kept from
  // carrying it below z = 0 (it lands on the plane); 0 after the drift.
  void apply_constraints(std::vector<Vec3d>& v, double time_ms, double drift_dt_ms);
  double kinetic_energy_mJ() const;
  void half_kick(std::vector<Vec3d>& v, double dt) const;  // v += dt/2 a, per particle (in parallel)

  SpgTissue& tissue_;
  std::unique_ptr<TissueMassScaling> mass_scaling_;
  std::unique_ptr<TissueRateLevels> rate_levels_;
  double cycle_dt_ms_ = std::numeric_limits<double>::infinity();  // the base step of the current cycle (multi-rate)
  std::vector<VelocityConstraint> constraints_;
  Eigen::Vector3d body_acceleration_;
  double time_ms_ = 0, first_dt_ms_ = 0, step_dt_ms_ = 0;
  bool drifted_ = false;  // between kick_and_drift and finish_step
  std::int64_t steps_ = 0;
  EnergyBalance energy_;
  std::vector<Vec3d> acceleration_;
  double impact_work_correction_mJ_ = 0;        // this step's: open symmetry particles stopped on the plane
  struct Landing {
    std::int32_t particle;
    double v_half_z;
  };
  std::vector<Landing> landed_;                 // this step's impacts on the plane
  std::vector<std::array<double, 3>> work_terms_;  // finish_step's scratch: each particle's model, external and body work
  std::vector<std::pair<std::int32_t, Vec3d>> impulse_shifts_;  // this step's: particles moved by impulses, and by how much
  std::vector<std::int32_t> constrained_;      // particles with a constrained component
  std::vector<std::uint8_t> constrained_mask_;  // per particle: bit k = component k constrained
  // Step scratch, kept to avoid allocating per step.
  std::vector<Vec3d> old_force_, displacement_, constrained_velocity_before_, constrained_velocity_half_;
  std::vector<Vec3d> external_force_, old_external_force_;
};

}  // namespace needle
