#pragma once
// The paper's card, LS-DYNA MAT_018 (TissueLaw::mat018): Hencky elasticity, then J2 plasticity on the power
// law sigma_y = rate_factor k (eps_yp + eps_p)^n with a Cowper-Symonds rate factor (tissue_material.h gives the
// card and its readings). One of the tissue laws update_stress dispatches to.
#include <Eigen/Dense>

#include "solver/tissue/tissue_material.h"

namespace needle {

// The deviatoric principal Cauchy stress of the elastic trial 2 mu h_dev, returned radially onto the yield
// surface where it lies beyond it: the plastic multiplier moves the principal log strain h and eps_p.
// rate: the increment's effective strain rate (1/ms), asked for only where it can matter; capped is set when the
// rate factor hit its cap.
Eigen::Vector3d mat018_deviatoric_stress(const TissueMaterial& m, const IncrementStrainRate& rate, const Eigen::Vector3d& h_dev,
                                         Eigen::Vector3d& h, double& eps_p, bool& capped);

// Whether a trial of von Mises stress q_trial stays elastic at any rate: within the yield stress at rate factor 1
// (the factor only raises it) with the rate unable to reach the factor's cap (rate_stays_uncapped), so the rate
// itself is not needed. mat018_deviatoric_stress returns 2 mu h_dev, uncapped, where this holds.
bool mat018_trial_stays_elastic(const TissueMaterial& m, const IncrementStrainRate& rate, double q_trial, double eps_p);
// Whether the rate factor stays below its cap over the increment, as m.rate_factor_uncapped_up_to(rate.upper_bound())
// says: without its two logarithms where |f f^T - I| lies below the norm at which the bound could reach the cap
// (both rise with the norm; the same answer, for the same results to the last bit).
bool rate_stays_uncapped(const TissueMaterial& m, const IncrementStrainRate& rate);
// The strain rate (1/ms) below which m.rate_factor_uncapped_up_to holds, less 1e-6 of it (infinite with no rate law).
double uncapped_rate_limit_per_ms(const TissueMaterial& m);

// The closed-form uniaxial curve (tissue_material.h: uniaxial_true_stress_MPa) of the card.
double mat018_uniaxial_true_stress_MPa(const TissueMaterial& m, double true_strain, double strain_rate_per_ms);

}  // namespace needle
