#pragma once
// The rigid needle (NeedleModel "rigid"): every node follows the drive, X + d(t) direction; no elastic
// forces, no cannula and no step limit (advance_to goes straight to its end time in one step). Model only
// what a scene needs: tissue studies that do not ask for deflection. Its drive's work is exactly what the
// motion needs (the change of kinetic energy less the loads' work), and its reaction is m dv/dt - f over
// all nodes, as the FE needle books its driven base.
#include <Eigen/Dense>

#include "solver/needle/fe_needle.h"
#include "solver/needle/insertion_profile.h"
#include "solver/needle/needle_model.h"

namespace needle {

class RigidNeedle : public NeedleModel {
 public:
  // The mesh and nodal masses of needle (which must outlive this), driven by profile along direction;
  // SolverError when the energy balance drifts beyond max_energy_error.
  RigidNeedle(const FeNeedle& needle, const InsertionProfile& profile, const Eigen::Vector3d& direction, double max_energy_error = 0.05);

  std::string name() const override { return "rigid"; }
  const TetMesh& mesh() const override { return needle_.mesh(); }
  const Eigen::VectorXd& nodal_mass_g() const override { return mass_; }
  double time_step_ms() const override { return std::numeric_limits<double>::infinity(); }
  void apply_loads(NeedleLoads& loads) override;
  void advance_to(double end_time_ms, NeedleLoads& loads) override;
  double time_ms() const override { return time_ms_; }
  long steps() const override { return steps_; }
  const Eigen::MatrixX3d& positions_mm() const override { return x_; }
  const Eigen::MatrixX3d& velocities_mm_per_ms() const override { return v_; }
  const NeedleEnergy& energy() const override { return energy_; }
  Eigen::Vector3d drive_displacement_mm() const override { return profile_.displacement_mm(time_ms_) * direction_; }
  Eigen::Vector3d drive_reaction_N() const override { return drive_reaction_; }
  Eigen::Vector3d drive_impulse_N_ms() const override { return drive_impulse_; }
  ElementStresses element_stresses() const override { return needle_.element_stresses(x_); }
  void add_summary(nlohmann::json& summary) const override;

 private:
  // The loads at the current state (x_, velocity, time_ms_) into external_ and force_.
  void evaluate_loads(NeedleLoads& loads, const Eigen::MatrixX3d& velocity);

  const FeNeedle& needle_;
  InsertionProfile profile_;
  Eigen::Vector3d direction_;
  double max_energy_error_;
  double time_ms_ = 0;
  long steps_ = 0;
  Eigen::VectorXd mass_;
  Eigen::MatrixX3d x_, v_, v_half_, v_before_, force_, old_force_;
  NodalForces external_, old_external_;
  NeedleEnergy energy_;
  Eigen::Vector3d drive_reaction_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d drive_impulse_ = Eigen::Vector3d::Zero();
};

}  // namespace needle
