#pragma once
// What the coupled insertion needs of a needle, whichever model moves it: its nodes (positions,
// velocities, masses) on the FE mesh's surface, its own stable step, `advance_to(t, loads)` under loads
// that depend on its state (the tissue's contact, re-evaluated at each of its own steps), its energy
// account and the drive's reaction. The explicit FE needle (needle_dynamics.h), the implicit linear needle
// (implicit_needle.h, the default model level's) and the rigid needle (rigid_needle.h) implement it;
// needle_models.h builds one by name. A new model is one file that implements this and one line in
// needle_models.cpp.
#include <Eigen/Dense>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <utility>
#include <vector>

#include "mesher/tet_mesh.h"
#include "solver/needle/fe_needle.h"

namespace needle {

// Forces on nodes, as (node, force in N) pairs; a node may appear more than once (the forces add).
using NodalForces = std::vector<std::pair<int, Eigen::Vector3d>>;

// The needle's energy account (mJ): kinetic + strain - initial = work of the drive + cannula + external loads.
struct NeedleEnergy {
  double kinetic_mJ = 0, strain_mJ = 0, initial_mJ = 0;
  double drive_work_mJ = 0, cannula_work_mJ = 0, external_work_mJ = 0;
  double held_mJ = 0;  // the kinetic energy the supports took when they held the needle still (held_needle.h)
  // |KE + U + E_held - E0 - W_drive - W_cannula - W_external| / the largest of those terms.
  double balance_error() const;
};

// Loads that depend on the needle's state, evaluated by the needle model at each of its own steps.
class NeedleLoads {
 public:
  virtual ~NeedleLoads() = default;
  // Appends the loads at positions x, (mid-step) velocities v and time t to force_N.
  virtual void needle_forces(const Eigen::MatrixX3d& x_mm, const Eigen::MatrixX3d& v_mm_per_ms, double time_ms, NodalForces& force_N) = 0;
};

class NeedleModel {
 public:
  virtual ~NeedleModel() = default;

  // The name it is registered under (needle_models.h).
  virtual std::string name() const = 0;
  // The mesh in its reference configuration (X, the surface's tags) and its lumped nodal masses.
  virtual const TetMesh& mesh() const = 0;
  virtual const Eigen::VectorXd& nodal_mass_g() const = 0;
  // Its own stable step; infinity when any step is stable (the rigid needle).
  virtual double time_step_ms() const = 0;
  // The grid a coupling step is cut to (a whole number of it), so that the model never takes a sliver of a
  // step: its own step for an explicit model; an implicit one takes any multiple of a finer grid.
  virtual double step_grid_ms() const { return time_step_ms(); }

  // The loads at the current state join the forces that start the next step (call once, at t = 0).
  virtual void apply_loads(NeedleLoads& loads) = 0;
  // Takes its own steps up to end_time_ms, re-evaluating loads at each.
  virtual void advance_to(double end_time_ms, NeedleLoads& loads) = 0;
  // Speculation, so that the coupled insertion can take the needle's next span beside the tissue's work (its solve is
  // serial): computes what advance_to(end_time_ms, loads) would give from the current state and keeps it, leaving the
  // state as it was. adopt_speculation(end_time_ms) then takes the kept result, bit for bit what advance_to would give,
  // if it was made from the current state to that time (true), and drops it either way; the caller must make sure the
  // loads would have been the same. A model that cannot (the default) returns false from both; so does a span that
  // failed (advance_to will then fail the same way). can_speculate says whether the model ever can.
  virtual bool can_speculate() const { return false; }
  virtual bool speculate_advance(double /*end_time_ms*/, NeedleLoads& /*loads*/) { return false; }
  virtual bool adopt_speculation(double /*end_time_ms*/) { return false; }

  virtual double time_ms() const = 0;
  virtual long steps() const = 0;
  virtual const Eigen::MatrixX3d& positions_mm() const = 0;
  virtual const Eigen::MatrixX3d& velocities_mm_per_ms() const = 0;
  virtual const NeedleEnergy& energy() const = 0;
  // Total momentum (g mm/ms), from the nodal masses and velocities.
  Eigen::Vector3d momentum() const {
    return (velocities_mm_per_ms().array().colwise() * nodal_mass_g().array()).colwise().sum().transpose();
  }
  // Where the driven base has moved the needle rigidly, and the force the drive applies (N).
  virtual Eigen::Vector3d drive_displacement_mm() const = 0;
  virtual Eigen::Vector3d drive_reaction_N() const = 0;
  // Its time integral since the start (N ms = g mm/ms): the momentum the drive has put in.
  virtual Eigen::Vector3d drive_impulse_N_ms() const = 0;
  // Stresses per element at the current state (frames).
  virtual ElementStresses element_stresses() const = 0;
  // The model's own entries in a run's summary.json (e.g. the FE needle's step and added mass).
  virtual void add_summary(nlohmann::json& summary) const = 0;

  Eigen::MatrixX3d displacements_mm() const { return positions_mm() - mesh().X; }
};

}  // namespace needle
