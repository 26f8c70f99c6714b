#pragma once
// The FE needle model (NeedleModel "fe"): explicit central-difference dynamics of the FE needle
// (velocity Verlet form, velocities at full steps for the energy balance), with the supports of an insertion: clamped nodes, a symmetry plane,
// the base plane driven by the insertion profile, and the rigid cannula.
//   v(n+1/2) = v(n) + dt/2 a(n);  supports;  x(n+1) = x(n) + dt v(n+1/2);
//   forces at x(n+1) (elastic + cannula);  v(n+1) = v(n+1/2) + dt/2 a(n+1);  supports.
// Driven nodes follow X + d(t) direction exactly. Energy balance:
//   kinetic + strain - (initial) = work of the drive's reaction + work of the cannula,
// whose relative error is the integrator's drift. The run stops with a SolverError (never NaN) on a
// non-finite state, on energy drift beyond a bound, or on cannula penetration beyond a bound.
#include <Eigen/Dense>
#include <optional>
#include <utility>
#include <vector>

#include "solver/needle/fe_needle.h"
#include "solver/needle/needle_model.h"
#include "solver/needle/insertion_profile.h"
#include "solver/needle/rigid_cannula.h"

namespace needle {

struct NeedleSupports {
  std::vector<int> clamped;   // all components held at zero velocity
  std::vector<int> symmetry;  // v_z = 0 (half model, z = 0 plane)
  std::vector<int> driven;    // follow the profile along direction
  InsertionProfile profile;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
};

// The insertion's supports on a needle mesh: the `base` face driven by the profile along direction,
// and the `symmetry` face (if the mesh is a half model) held at v_z = 0.
NeedleSupports driven_base_supports(const TetMesh& mesh, const InsertionProfile& profile,
                                    const Eigen::Vector3d& direction = Eigen::Vector3d::UnitX());

struct NeedleDynamicsOptions {
  double courant = 0.9;                 // fraction of the stable step used
  double max_energy_error = 0.05;       // stop when the balance error exceeds this (after the first work)
  double max_penetration_mm = 0.05;     // stop when a node passes the cannula's bore by more
  double implicit_step_ms = 0.0;        // the implicit needle's step (implicit_needle.h; > 0 to use it); the coupling step is a whole number of them
};

class NeedleDynamics : public NeedleModel {
 public:
  NeedleDynamics(const FeNeedle& needle, NeedleSupports supports, const std::optional<CannulaOptions>& cannula,
                 const NeedleDynamicsOptions& options = {});

  std::string name() const override { return "fe"; }
  const TetMesh& mesh() const override { return needle_.mesh(); }
  const Eigen::VectorXd& nodal_mass_g() const override { return mass_; }
  double time_step_ms() const override { return dt_ms_; }
  // Replaces the state before the first step (a pre-deformed or moving start); InputError after.
  void set_initial_state(const Eigen::MatrixX3d& x_mm, const Eigen::MatrixX3d& v_mm_per_ms);
  // One step of time_step_ms() (shortened to land on end_time_ms if given).
  void step(double end_time_ms = std::numeric_limits<double>::infinity());
  // Steps until end_time_ms (subcycling within a longer step of another body) under the loads last given.
  void advance_to(double end_time_ms);
  // NeedleModel: the loads (the tissue's contact), evaluated with the elastic forces at every step (positions,
  // mid-step velocities, time); apply_loads evaluates them at once, before the first step or between steps.
  void apply_loads(NeedleLoads& loads) override;
  void advance_to(double end_time_ms, NeedleLoads& loads) override;

  double time_ms() const override { return time_ms_; }
  long steps() const override { return steps_; }
  const Eigen::MatrixX3d& positions_mm() const override { return x_; }
  const Eigen::MatrixX3d& velocities_mm_per_ms() const override { return v_; }
  const NeedleEnergy& energy() const override { return energy_; }
  const CannulaContact& cannula_contact() const { return contact_; }
  // Force the drive applies to the needle through the driven nodes (N): m a - f over those nodes.
  Eigen::Vector3d drive_reaction_N() const override { return drive_reaction_; }
  // Its time integral since the start (N ms = g mm/ms): the momentum the drive has put in.
  Eigen::Vector3d drive_impulse_N_ms() const override { return drive_impulse_; }
  // Where the driven base has moved the needle rigidly: d(t) direction.
  Eigen::Vector3d drive_displacement_mm() const override { return supports_.profile.displacement_mm(time_ms_) * supports_.direction; }
  ElementStresses element_stresses() const override { return needle_.element_stresses(x_); }
  void add_summary(nlohmann::json& summary) const override;
  const FeNeedle& needle() const { return needle_; }

 private:
  void apply_supports(Eigen::MatrixX3d& v, double time_ms) const;
  void compute_forces(const Eigen::MatrixX3d& velocity);

  const FeNeedle& needle_;
  NeedleSupports supports_;
  std::optional<RigidCannula> cannula_;
  NeedleDynamicsOptions options_;
  double dt_ms_ = 0, time_ms_ = 0;
  long steps_ = 0;
  Eigen::MatrixX3d x_, v_, a_, force_, old_force_, cannula_force_, old_cannula_force_;
  NeedleLoads* loads_ = nullptr;  // the loads last given (none: no external forces)
  NodalForces external_, old_external_;
  Eigen::MatrixX3d v_before_;  // step scratch: velocities of the constrained nodes before the step
  Eigen::MatrixX3d v_half_;
  Eigen::VectorXd mass_;
  std::vector<std::uint8_t> mask_;  // per node: bit k = component k prescribed
  std::vector<int> constrained_;
  NeedleEnergy energy_;
  CannulaContact contact_;
  Eigen::Vector3d drive_reaction_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d drive_impulse_ = Eigen::Vector3d::Zero();
};

}  // namespace needle
