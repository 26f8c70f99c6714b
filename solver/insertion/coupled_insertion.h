#pragma once
// The L-SPG insertion: a needle model (needle/needle_model.h: the explicit FE needle, the implicit linear one
// or the rigid one) driven into the SPG tissue (tissue/spg_tissue.h, tissue/tissue_dynamics.h) through a
// contact law (contact/needle_tissue_contact.h: the frictional penalty, or the kinematic projection of the
// default model level), the tissue separated after each step by the scene's separation models
// (separation/separation_models.h), in one explicit run with two clocks. The coupled step, as step() reads:
//   1. plan dt: the tissue's stable step, capped by the contact law's limit (the penalty's: contact_courant of
//      its own; a kinematic law has none) and the end time, cut to a whole number of the needle's step grid;
//   2. the tissue's first half of velocity Verlet: half kick and drift to its end positions;
//   3. the contact begins the step: geometry from both bodies (particles at their end, needle at its start);
//   4. the needle advances to t + dt under the contact's loads, subcycling at its own step (the contact's
//      gap is updated from both bodies' motion at every needle step); beside it, on the other threads, the
//      particles away from the needle update their stresses (step 6's first stage, which the contact cannot change);
//   5. the contact ends the step: its force at t + dt on the particles (penalty) or its impulses (projection);
//   6. the tissue's second half: its forces at t + dt with the contact's, the half kick;
//   5b. a fired cannula (cannula_firing.h), when there is one, pushes the tissue out of its wall;
//   7. each separation model separates the tissue (the needle's cut, the slit, the crack, the lip's release, a fired
//      cannula's edge);
//   8. the energy account, penetration and drift checks (each body checks its own NaN and blow-up).
// Each step, the needle receives -C(t) over its substeps and the tissue (C(t) + C(t + dt)) dt / 2: momentum
// is exchanged exactly up to a half-step lag that never accumulates (it telescopes to dt/2 |C(end) - C(0)|).
// The lag is stable because the steel's response to a force within one tissue step is tiny next to the
// contact's own stiffness (the loop gain is k_contact / K_steel, about 1e-3). With subcycling off, both
// bodies take the needle's step: the plain full model the subcycled one is measured against (bench_insertion).
// The run stops with a SolverError (never NaN) on non-finite state, runaway penetration, time-step collapse
// or energy drift (insertion_energy.h).
#include <Eigen/Dense>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "solver/contact/cutting_resistance.h"
#include "solver/contact/needle_tissue_contact.h"
#include "solver/insertion/cannula_firing.h"
#include "solver/insertion/insertion_energy.h"
#include "solver/needle/needle_model.h"
#include "solver/separation/separation_model.h"
#include "solver/tissue/tissue_dynamics.h"

namespace needle {

struct CouplingOptions {
  bool subcycling = true;       // false: the tissue takes the needle's step (plain full model)
  double max_step_ms = 0.0;     // cap on the coupling step (0: the tissue's and the contact's limits only)
  double contact_courant = 0.1; // fraction of the contact's own stable step (2 sqrt(m/k)) a coupling step may
                                // take: the accuracy knob of the subcycling (its error is first order in it)
  double max_energy_error = 0.05;    // stop when the physical balance drifts beyond this (once the work from outside exceeds the energy at t = 0)
  double max_depth_mm = 0.3;         // stop when a particle gets this deep inside the needle
  double tissue_mass_scaling_dt_ms = 0.0;  // the tissue's selective mass scaling to this step (0: none; tissue_mass_scaling.h)
  Eigen::Vector3d tissue_body_acceleration_mm_per_ms2 = Eigen::Vector3d::Zero();  // e.g. to press a block on
  // Step 4 runs beside the stress update of the particles away from the needle (its solve is serial), which the
  // contact cannot move: the same result, bit for bit, as one after the other (false: one after the other).
  // Away: their whole support lies outside the needle's box at the step's start (with a half model's mirror image), widened by the contact's skin,
  // twice the needle's largest node motion of the last step and this margin; a run in which the contact moves
  // a particle there stops with a SolverError.
  bool tissue_beside_needle = true;
  double tissue_ahead_margin_mm = 0.1;
  // The needle's next span is taken beside the tissue's force update at the end of each step, on the guess that the
  // next coupling step is as long as this one (true most steps: the steps are whole eighths of the implicit needle's
  // and sit at the mass scaling's floor), and adopted when the guess holds: the same result, bit for bit, as
  // without. Only where the needle's loads over a step are set at the last step's end (a kinematic contact, no
  // cutting resistance) and the model can speculate (the implicit needle); false: never.
  bool needle_ahead = true;
  // Multi-rate stepping of the tissue (tissue/tissue_rate_levels.h): the slowest points update every 2^levels
  // coupling steps (0: every point every step). The particles within this margin of the needle's box (widened by
  // the contact's skin) are held at the coupling step; negative: none held, the levels follow the particles' own
  // stable steps alone.
  int tissue_rate_levels = 0;
  double tissue_rate_needle_margin_mm = 0.2;
  double tissue_rate_safety = 1.0;  // a particle's period at most its own stable step over this
  void validate(const std::string& where = "coupling") const;
};

// What set a coupling step (issue 48: whatever limits the step is named): the end of the interval it lands on, the
// scene's max_coupling_step, the penalty contact's stable step, the needle's own step (without subcycling), or the
// tissue's stable step (mass-scaled, and within a cycle of the rate levels its base step). The step is then rounded
// down to a whole number of the needle's grid (a rounding, not a limit).
enum class StepLimit { interval_end, max_step, contact, needle_step, tissue };
constexpr int kStepLimits = 5;
const char* step_limit_name(StepLimit limit);  // "interval_end", ...

class CoupledInsertion {
 public:
  // The needle, the tissue and the surface are advanced or read by this object; they must outlive it.
  // The cutting resistance (contact/cutting_resistance.h) joins the contact as a load on the needle when enabled.
  CoupledInsertion(NeedleModel& needle, SpgTissue& tissue, const ContactSurface& surface, const ContactOptions& contact,
                   std::vector<std::unique_ptr<SeparationModel>> separations, const CouplingOptions& coupling,
                   const CuttingOptions& cutting = {});

  // The cannula fired over the needle after its travel (cannula_firing.h), before the first step; it must outlive this
  // object, and its edge's cut is one of the separation models (separation/cannula_edge_cut.h). Null: none.
  void fire_cannula(CannulaFiring* firing);
  const CannulaFiring* cannula_firing() const { return firing_; }

  // One coupling step, shortened to land on end_time_ms.
  void step(double end_time_ms);

  double time_ms() const { return tissue_dynamics_.time_ms(); }
  long steps() const { return steps_; }
  double last_step_ms() const { return last_dt_ms_; }
  // How many coupling steps each limit set, by StepLimit.
  const std::array<long, kStepLimits>& step_limits() const { return step_limits_; }
  // How many of the needle's spans were taken ahead, beside the tissue's update (CouplingOptions::needle_ahead).
  long needle_spans_ahead() const { return needle_spans_ahead_; }
  long needle_steps() const { return needle_.steps(); }
  // The loads on the needle at the last evaluation: the contact's, with the cutting resistance's added in.
  ContactReport contact() const;
  NeedleTissueContact& contact_model() { return *contact_; }
  const NeedleTissueContact& contact_model() const { return *contact_; }
  const InsertionEnergy& energy() const { return energy_; }
  double max_energy_error() const { return max_energy_error_; }
  int max_particles_inside() const { return max_inside_; }
  double max_depth_mm() const { return max_depth_; }
  long bonds_broken() const { return static_cast<long>(tissue_.bonds().broken_count); }
  const std::vector<std::unique_ptr<SeparationModel>>& separations() const { return separations_; }
  const CuttingResistance* cutting() const { return cutting_.get(); }  // null when cutting costs nothing
  // Momenta (g mm/ms).
  Eigen::Vector3d tissue_momentum() const;
  Eigen::Vector3d needle_momentum() const { return needle_.momentum(); }
  const NeedleModel& needle() const { return needle_; }
  const SpgTissue& tissue() const { return tissue_; }
  const TissueDynamics& tissue_dynamics() const { return tissue_dynamics_; }
  TissueDynamics& tissue_dynamics() { return tissue_dynamics_; }

 private:
  double plan_time_step(double end_time_ms, StepLimit& limit) const;
  // One flag per particle: whether it lies inside (inside true) or outside the needle's box (with a half model's
  // mirror image) widened by margin_mm.
  void flag_particles_by_needle_box(double margin_mm, bool inside, std::vector<std::uint8_t>& flags) const;
  // Flags the particles away from the needle (CouplingOptions::tissue_beside_needle) into still_.
  void mark_particles_away_from_needle();
  double cannula_reach_mm() const;  // how far beyond the needle's box a fired cannula may move particles now
  static constexpr double kCannulaReachSafetyMm = 0.05;
  // Holds the particles near the needle at the coupling step for the next cycle of the rate levels.
  void hold_particles_near_needle_fast();
  void check_health();  // penetration and the energy balance; SolverError beyond their limits

  NeedleModel& needle_;
  SpgTissue& tissue_;
  CouplingOptions options_;
  TissueDynamics tissue_dynamics_;
  std::unique_ptr<NeedleTissueContact> contact_;  // the law the contact options name (contact_laws.h)
  std::unique_ptr<CuttingResistance> cutting_;
  // What the needle feels in a step: the contact, then the cutting resistance.
  struct StepLoads : NeedleLoads {
    NeedleTissueContact* contact = nullptr;
    CuttingResistance* cutting = nullptr;
    void needle_forces(const Eigen::MatrixX3d& x_mm, const Eigen::MatrixX3d& v_mm_per_ms, double time_ms, NodalForces& force_N) override;
  } loads_;
  std::vector<std::unique_ptr<SeparationModel>> separations_;
  CannulaFiring* firing_ = nullptr;
  std::vector<Vec3d> contact_force_N_;  // the contact's force on each particle at the step's end
  std::vector<std::uint8_t> still_;     // particles away from the needle this step
  // Whether the needle's next span is taken ahead, beside the tissue's update at this step's end (needle_ahead).
  bool take_next_needle_span_ahead(double next_start_ms, double dt_ms) const;
  bool adopt_needle_span(double end_time_ms);  // the span taken ahead to end_time_ms, if there is one (counted)
  long needle_spans_ahead_ = 0;         // the spans taken ahead and adopted
  Eigen::MatrixX3d needle_x_before_;    // the needle's nodes at the last step's start
  double needle_motion_mm_ = 0;         // the largest node motion over the last step
  InsertionEnergy energy_;
  double last_dt_ms_ = 0, max_energy_error_ = 0, max_depth_ = 0;
  int max_inside_ = 0;
  long steps_ = 0;
  std::array<long, kStepLimits> step_limits_{};
};

}  // namespace needle
