#pragma once
// Uniaxial tension of a particle specimen, the way a user checks a tissue card before trusting it:
// an ASTM D412-like gauge section (16.5 mm long) pulled at a constant true strain rate by its end
// layers (lubricated grips: x prescribed), starting from the matching velocity field so that no
// start-up wave runs through it.
//
// Lateral faces: `guided` (default) moves every particle's y and z homogeneously, at the rate that a
// servo sets each step to keep the mean lateral stress at zero: a uniaxial stress state that cannot
// neck. `free` leaves them free, as a real specimen: a MAT_018 card is linear up to eps_yp and its
// tangent never exceeds E, so a free bar passes the Considere force maximum (for the paper's card near
// eps = 1.1: P ~ eps exp(-2 nu eps)) and necks; the curve then describes the neck, not the material.
//   true strain = ln(L / L0) between the grips;
//   true stress = grip force / current cross-section (A0 times the lateral stretches measured at
//                 mid-length), i.e. measured the way the test machine does, not read from the particles.
// The particles' own mean sigma_xx in the middle third is reported beside it.
#include <cstdint>
#include <vector>

#include "solver/tissue/spg_options.h"
#include "solver/tissue/tissue_material.h"

namespace needle {

struct UniaxialTestOptions {
  double length_mm = 16.5;
  double width_mm = 3.0;
  double thickness_mm = 3.0;
  double spacing_mm = 0.75;
  double max_strain = 1.5;
  double strain_rate_per_ms = 0.05;  // 50 /s: quasi-static (inertia < 0.3 % of stress), fast to run
  int samples = 31;                  // curve points from 0 to max_strain
  bool guided_lateral = true;
  SpgOptions spg;
  void validate() const;
};

struct UniaxialCurve {
  std::vector<double> true_strain;
  std::vector<double> true_stress_MPa;           // grip force / current area
  std::vector<double> particle_stress_MPa;       // mean particle sigma_xx, middle third
  std::vector<double> closed_form_stress_MPa;    // uniaxial_true_stress_MPa of the card at the same strain
  std::vector<double> plastic_strain;            // mean particle eps_p, middle third
  std::vector<double> lateral_stress_MPa;        // mean particle (sigma_yy + sigma_zz) / 2, middle third
  std::int64_t particles = 0, neighbours = 0, steps = 0, bonds_broken = 0, rate_factor_capped = 0;
  double runtime_s = 0;
  double max_energy_error = 0;
  // max |stress - closed form| / max(closed form over the curve) over the samples (a relative error
  // that does not blow up at zero stress)
  double max_relative_error() const;
};

// InputError for bad options or material; SolverError if the specimen blows up.
UniaxialCurve run_uniaxial_test(const TissueMaterial& material, const UniaxialTestOptions& options);

}  // namespace needle
