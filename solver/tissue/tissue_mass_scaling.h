#pragma once
// Selective mass scaling of the tissue (LS-DYNA's DT2MS for particles): a particle whose own stable step
// falls below the step the tissue takes gets mass, m = m0 (dt / dt_i)^2, so that its step reaches dt;
// the others keep their physical mass m0. Under the needle a few particles are squeezed to a fifth of
// their spacing, and their step (length over wave speed) would set everybody's: scaling them lets the
// whole block take the target step. It is a numerical parameter (an inertia error where particles are
// squeezed), so its effect on the deflection is measured, not assumed (docs/insertion.md).
//
// The masses follow the deformation: each step they are set anew from the particles' current steps, so
// a particle released behind the tip gets its physical mass back. A particle that gains mass keeps its
// momentum (v = m_old v / m_new on its free components; a constrained component keeps its prescribed
// velocity), one that loses mass keeps its velocity: either way kinetic energy is lost, never made (a
// particle handing back 25 times its mass with its momentum would leave 25 times as fast). The energy the
// changes remove is booked apart, so the energy balance still closes.
#include <cstdint>
#include <vector>

#include "solver/tissue/spg_tissue.h"

namespace needle {

struct MassScalingReport {
  std::int64_t scaled_particles = 0;  // now
  double added_mass_g = 0;            // now, over all particles
  double max_added_mass_g = 0;        // the most added at once over the run
  double max_ratio = 1;               // the largest m / m0 over the run
  // The same two over the crushed particles only (kParticleCrushed, the lip below a tip point): where a
  // material with no shear stiffness is sheared flat, its step is short and its added mass large.
  double max_added_mass_crushed_g = 0;
  double max_ratio_crushed = 1;
  double energy_mJ = 0;               // kinetic energy the mass changes added over the run (<= 0: they remove it)
};

class TissueMassScaling {
 public:
  // target_dt_ms > 0: the step below which particles get mass. The physical masses are the particles' now.
  TissueMassScaling(double target_dt_ms, const TissueParticles& particles);

  double target_dt_ms() const { return target_dt_ms_; }
  // A new target from the next step on (the masses are set anew each step from it).
  void set_target_dt_ms(double target_dt_ms);
  // The step the tissue may take given its own unscaled stable step: the larger of the two.
  double time_step_ms(double unscaled_stable_dt_ms) const;
  // Sets the masses for a step of dt_ms from the particles' own steps (SpgTissue::particle_time_steps_ms),
  // keeping momentum on the components whose bit in constrained_mask (one per particle, bit k: component k
  // held) is clear. Returns the particles whose mass changed, for the caller to refresh their accelerations.
  const std::vector<std::int32_t>& apply(double dt_ms, const SpgTissue& tissue, TissueParticles& particles,
                                         const std::vector<std::uint8_t>& constrained_mask);
  const MassScalingReport& report() const { return report_; }
  double physical_mass_g() const { return physical_mass_total_g_; }

 private:
  double target_dt_ms_;
  std::vector<double> physical_mass_g_;
  double physical_mass_total_g_ = 0;
  std::vector<double> particle_dt_ms_;      // scratch
  std::vector<std::int32_t> changed_;       // scratch
  std::vector<std::int32_t> scaled_;        // particles heavier than physical now
  MassScalingReport report_;
};

}  // namespace needle
