#pragma once
// A needle model that runs another one until a time, then holds the needle still where it is: the trucut's stop at
// the end of the needle's throw, before the cannula is fired over it (solver/insertion/cannula_firing.h).
//
// Until hold_from_ms every call is the inner model's, bit for bit. From then on the nodes keep their positions at rest:
// the device holds the needle. The steel's ringing after a stop without deceleration (its kinetic energy, undamped,
// kept for ever by the inner model) is taken out with that energy, booked as the energy the supports took (NeedleEnergy::
// held_mJ, stored beside the strain energy), so the run's energy account stays closed and keeps its scale; the strain
// energy stays as it was. The loads are still evaluated at each step (at zero
// velocity), so a contact law's own account goes on, and the reaction the supports give is their sum, negated.
#include <algorithm>
#include <memory>

#include "solver/needle/needle_model.h"

namespace needle {

class HeldNeedle : public NeedleModel {
 public:
  HeldNeedle(std::unique_ptr<NeedleModel> inner, double hold_from_ms);

  std::string name() const override { return inner_->name(); }
  const TetMesh& mesh() const override { return inner_->mesh(); }
  const Eigen::VectorXd& nodal_mass_g() const override { return inner_->nodal_mass_g(); }
  double time_step_ms() const override { return inner_->time_step_ms(); }
  double step_grid_ms() const override { return inner_->step_grid_ms(); }
  void apply_loads(NeedleLoads& loads) override { inner_->apply_loads(loads); }
  void advance_to(double end_time_ms, NeedleLoads& loads) override;
  // The inner model's, for a span that ends before the hold.
  bool can_speculate() const override { return !held_ && inner_->can_speculate(); }
  bool speculate_advance(double end_time_ms, NeedleLoads& loads) override;
  bool adopt_speculation(double end_time_ms) override;
  double time_ms() const override { return held() ? time_ms_ : inner_->time_ms(); }
  long steps() const override { return inner_->steps(); }
  const Eigen::MatrixX3d& positions_mm() const override { return inner_->positions_mm(); }
  const Eigen::MatrixX3d& velocities_mm_per_ms() const override { return held() ? still_ : inner_->velocities_mm_per_ms(); }
  const NeedleEnergy& energy() const override { return held() ? energy_ : inner_->energy(); }
  Eigen::Vector3d drive_displacement_mm() const override { return inner_->drive_displacement_mm(); }
  Eigen::Vector3d drive_reaction_N() const override { return held() ? reaction_N_ : inner_->drive_reaction_N(); }
  Eigen::Vector3d drive_impulse_N_ms() const override { return inner_->drive_impulse_N_ms() + held_impulse_N_ms_; }
  ElementStresses element_stresses() const override { return inner_->element_stresses(); }
  void add_summary(nlohmann::json& summary) const override;

  bool held() const { return held_; }
  // Whether time_ms lies before the hold (within the rounding of summed steps: 1e-12 of it).
  bool before_hold(double time_ms) const { return time_ms < hold_from_ms_ - 1e-12 * std::max(1.0, hold_from_ms_); }
  double hold_from_ms() const { return hold_from_ms_; }
  double kinetic_energy_taken_mJ() const { return taken_mJ_; }  // the inner model's at the hold

 private:
  void hold();

  std::unique_ptr<NeedleModel> inner_;
  double hold_from_ms_, time_ms_ = 0, taken_mJ_ = 0;
  bool held_ = false;
  Eigen::MatrixX3d still_;
  NeedleEnergy energy_;
  Eigen::Vector3d reaction_N_ = Eigen::Vector3d::Zero(), held_impulse_N_ms_ = Eigen::Vector3d::Zero();
  NodalForces forces_;
};

}  // namespace needle
