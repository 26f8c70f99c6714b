#pragma once
// The implicit needle (NeedleModel "implicit"): the FE needle's mesh and masses, linear elastic (its
// stiffness K at the reference configuration), stepped by Newmark's average-acceleration rule on a
// factored matrix, so that it keeps up with the tissue's step without subcycling (the explicit FE needle
// takes about 2 000 steps of the steel's stable step per tissue step under a kinematic contact).
//
// Displacements are measured from the drive's rigid motion: x = X + d(t) e + w, w = 0 on the driven base
// and w_z = 0 on the symmetry plane. K annihilates rigid translations, so on the free components
//   M w'' + K w = f(x, v) - M e d''(t)
// (the drive's acceleration is an inertial load on every free node). With the step h fixed,
//   (K + 4 M / h^2) w(n+1) = f + M (4 / h^2 w(n) + 4 / h w'(n) + w''(n)),
// unconditionally stable and free of numerical damping; the matrix is factored once per distinct step
// (CHOLMOD) and the last six are kept: a kinematic contact's coupled step takes equal steps to each record
// (coupled_insertion.h), so the steps repeat and a run factors a few times (the summary says how often).
// A span longer than h is taken in equal steps of at most h. The loads f (the tissue's contact and the cannula's penalty) are evaluated at the start of
// each step and held over it: a one-step lag. A kinematic contact's load is constant over a coupling step
// anyway; the cannula's penalty is explicit, so its stiffness follows this step, k_i = scale m_i / h^2
// (rigid_cannula.h): softer than at the explicit needle's step, which the run's cannula penetration reports.
//
// Errors against the explicit, geometrically nonlinear FE needle: small rotations (the paper's needles
// turn by about 0.05 rad: a relative error of order 1e-3), and the period error of the trapezoidal rule,
// (omega dt)^2 / 12, below 1e-5 for the first bending mode at the tissue's step (about 5e-3 ms at most). Measured in the tests against the
// FE needle under a static and a dynamic tip load.
// Energy: kinetic + strain (1/2 w.K w) = work of the drive's reaction (from the needle's momentum balance),
// the cannula's and the external loads' (trapezoid of the held forces over each step); the run stops with
// a SolverError beyond max_energy_error, on a non-finite state or on cannula penetration beyond its bound.
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <memory>
#include <optional>
#include <vector>

#include "solver/needle/needle_dynamics.h"

namespace needle {

class ImplicitNeedle : public NeedleModel {
 public:
  // Clamped supports are not supported (InputError): the insertion drives the base.
  ImplicitNeedle(const FeNeedle& needle, NeedleSupports supports, const std::optional<CannulaOptions>& cannula,
                 const NeedleDynamicsOptions& options = {});
  ~ImplicitNeedle() override;

  std::string name() const override { return "implicit"; }
  const TetMesh& mesh() const override { return needle_.mesh(); }
  const Eigen::VectorXd& nodal_mass_g() const override { return mass_; }
  double time_step_ms() const override { return step_ms_; }
  void apply_loads(NeedleLoads& loads) override;
  void advance_to(double end_time_ms, NeedleLoads& loads) override;

  double time_ms() const override { return time_ms_; }
  long steps() const override { return steps_; }
  const Eigen::MatrixX3d& positions_mm() const override { return x_; }
  const Eigen::MatrixX3d& velocities_mm_per_ms() const override { return v_; }
  const NeedleEnergy& energy() const override { return energy_; }
  Eigen::Vector3d momentum() const override { return (v_.array().colwise() * mass_.array()).colwise().sum().transpose(); }
  Eigen::Vector3d drive_displacement_mm() const override { return supports_.profile.displacement_mm(time_ms_) * supports_.direction; }
  Eigen::Vector3d drive_reaction_N() const override { return drive_reaction_; }
  Eigen::Vector3d drive_impulse_N_ms() const override { return drive_impulse_; }
  ElementStresses element_stresses() const override { return needle_.element_stresses(x_); }
  void add_summary(nlohmann::json& summary) const override;

  const CannulaContact& cannula_contact() const { return contact_; }
  int factorizations() const { return factorizations_; }
  double factor_seconds() const { return factor_s_; }

 private:
  struct Factor;
  void step(double dt, NeedleLoads& loads);
  Factor& factor_for(double dt);  // the factored step matrix for dt, from the cache or new
  // The held loads at the current state: contact (loads) + cannula, into f_ (3 per node) and the lists.
  void evaluate_loads(NeedleLoads& loads);
  void update_state();        // x_, v_ from w, w' and the drive
  void start_accelerations();  // w'' in equilibrium with the held loads at the current state

  const FeNeedle& needle_;
  NeedleSupports supports_;
  NeedleDynamicsOptions options_;
  double step_ms_ = 0;
  Eigen::VectorXd mass_;
  std::optional<RigidCannula> cannula_;
  CannulaContact contact_;
  std::vector<int> free_dof_;              // free components, as 3 node + axis
  Eigen::SparseMatrix<double> K_;          // full stiffness (strain energy, reactions)
  Eigen::SparseMatrix<double> K_free_;     // on the free components, lower triangle
  Eigen::VectorXd mass_free_;
  std::vector<std::pair<double, std::unique_ptr<Factor>>> factors_;  // by step, the last used first
  double factor_s_ = 0;
  int factorizations_ = 0;
  Eigen::VectorXd w_, wd_, wdd_;           // on all 3 n components
  Eigen::VectorXd load_, cannula_load_;    // held over the current step (3 n)
  Eigen::VectorXd old_load_, old_cannula_load_;
  NodalForces external_;
  Eigen::MatrixX3d x_, v_;
  double time_ms_ = 0;
  long steps_ = 0;
  NeedleEnergy energy_;
  Eigen::Vector3d drive_reaction_ = Eigen::Vector3d::Zero(), drive_impulse_ = Eigen::Vector3d::Zero();
};

}  // namespace needle
