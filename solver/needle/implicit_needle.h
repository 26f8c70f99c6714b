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
// (CHOLMOD) and the last ten are kept: a span is taken in steps of h and one remainder, and the coupled step
// is a whole number of eighths of h (step_grid_ms), so a run factors at most nine times (the summary says how
// often). The tissue's contact load is evaluated at the start of
// each step and held over it (a kinematic contact's load is constant over a coupling step anyway).
// The cannula (rigid_cannula.h: a tube of inner radius r along x) is implicit in its normal direction: a
// surface node inside its length whose radius would pass r is held by a spring k_i = scale m_i / dt_FE^2 (the
// FE needle's own cannula, dt_FE the explicit needle's step) along the radial n_i, linearised at the step's
// predicted state: (A + sum k_i n_i n_i^T) w = b + sum k_i (r - n_i.(X_i + d e)) n_i, solved by the Woodbury
// identity on the factor of A with the columns A^-1 e of the nodes in contact (cached per factor), the set
// of nodes in contact iterated until it holds (a node that would pull leaves it, one that passes joins it).
// Its Coulomb friction, min(mu f_n, m |v_t| / (2 h)), uses the last step's normal force and is held.
//
// Errors against the explicit, geometrically nonlinear FE needle: small rotations (the paper's needles
// turn by about 0.05 rad: a relative error of order 1e-3), and the period error of the trapezoidal rule,
// (omega h)^2 / 12, about 1e-6 for the first bending mode at h = 1e-3 ms. Measured in the tests against the
// FE needle under a static and a dynamic tip load.
// Energy: kinetic + strain (1/2 w.K w, from the step's own equation: no product with K) = work of the drive's reaction (from the needle's momentum balance),
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
  // An eighth of its step: a span is taken in steps of h and one remainder, a whole number of eighths.
  double step_grid_ms() const override { return step_ms_ / 8; }
  void apply_loads(NeedleLoads& loads) override;
  void advance_to(double end_time_ms, NeedleLoads& loads) override;
  bool can_speculate() const override { return true; }
  bool speculate_advance(double end_time_ms, NeedleLoads& loads) override;
  bool adopt_speculation(double end_time_ms) override;

  double time_ms() const override { return state_.time_ms; }
  long steps() const override { return state_.steps; }
  const Eigen::MatrixX3d& positions_mm() const override { return state_.x; }
  const Eigen::MatrixX3d& velocities_mm_per_ms() const override { return state_.v; }
  const NeedleEnergy& energy() const override { return state_.energy; }
  Eigen::Vector3d drive_displacement_mm() const override { return supports_.profile.displacement_mm(state_.time_ms) * supports_.direction; }
  Eigen::Vector3d drive_reaction_N() const override { return state_.drive_reaction; }
  Eigen::Vector3d drive_impulse_N_ms() const override { return state_.drive_impulse; }
  ElementStresses element_stresses() const override { return needle_.element_stresses(state_.x); }
  void add_summary(nlohmann::json& summary) const override;

  const CannulaContact& cannula_contact() const { return state_.contact; }
  double max_cannula_penetration_mm() const { return state_.max_cannula_penetration_mm; }
  // The matrix a step of dt factors, K + 4 M / dt^2 on the free components (lower triangle): bench_needle times its
  // factorisations.
  Eigen::SparseMatrix<double> step_matrix(double dt) const;
  int factorizations() const { return factorizations_; }
  double factor_seconds() const { return factor_s_; }

 private:
  struct Factor;
  void step(double dt, NeedleLoads& loads);
  Factor& factor_for(double dt);  // the factored step matrix for dt, from the cache or new
  // The held loads at the current state: the contact's (loads) into state_.load, the cannula's friction into its cannula_load.
  void evaluate_loads(NeedleLoads& loads);
  // The cannula's normal springs on the free components solved into w (free components), iterating the set of
  // nodes in contact; their forces at t + dt are added to state_.cannula_load. drive_mm: d(t + dt) e. Returns the
  // springs' (g - U U^T w).w of the system solved last (step's strain energy).
  double hold_in_cannula(Factor& factor, Eigen::VectorXd& w, const Eigen::Vector3d& drive_mm);
  const Eigen::VectorXd& column(Factor& factor, int dof);  // A^-1 e_dof on the free components, cached
  void update_state();        // the state's x, v from w, w' and the drive
  void start_accelerations();  // w'' in equilibrium with the held loads at the current state

  // Everything a step changes, in one place so that a span can be taken ahead and kept (the factor cache and its
  // counts aside: the same factors either way).
  struct State {
    Eigen::VectorXd w, wd, wdd;                   // on all 3 n components
    Eigen::VectorXd load, cannula_load;           // held over the current step (3 n)
    Eigen::VectorXd old_load, old_cannula_load;
    Eigen::VectorXd cannula_normal_N;             // per node (all): the last step's normal force magnitude
    Eigen::MatrixX3d x, v;
    NodalForces external;
    CannulaContact contact;
    double max_cannula_penetration_mm = 0, time_ms = 0;
    long steps = 0;
    NeedleEnergy energy;
    Eigen::Vector3d drive_reaction = Eigen::Vector3d::Zero(), drive_impulse = Eigen::Vector3d::Zero();
  };

  const FeNeedle& needle_;
  NeedleSupports supports_;
  NeedleDynamicsOptions options_;
  double step_ms_ = 0;
  Eigen::VectorXd mass_;
  std::optional<CannulaOptions> cannula_;
  std::vector<int> cannula_nodes_;         // surface nodes
  std::vector<double> cannula_k_;          // per node: the normal spring (N/mm)
  std::vector<int> free_index_;            // per component: its free index, -1 held
  std::vector<int> free_dof_;              // free components, as 3 node + axis
  Eigen::SparseMatrix<double> K_;          // full stiffness (the accelerations in equilibrium with the loads)
  Eigen::SparseMatrix<double> K_free_;     // on the free components, lower triangle
  Eigen::VectorXd mass_free_;
  std::vector<std::pair<double, std::unique_ptr<Factor>>> factors_;  // by step, the last used first
  double factor_s_ = 0;
  int factorizations_ = 0;
  State state_;
  // The kept speculation: made from the state at (steps, time) to end_ms.
  std::optional<State> speculation_;
  long speculation_from_steps_ = -1;
  double speculation_from_ms_ = 0, speculation_end_ms_ = 0;
};

}  // namespace needle
