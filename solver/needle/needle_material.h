#pragma once
// The needle's steel: linear elastic (AISI 304 in the paper). Used through a Saint Venant-Kirchhoff
// law in the total-Lagrangian element (fe_needle.h), which is linear elasticity for small strains and
// exact under large rotations.
#include <string>

namespace needle {

struct NeedleMaterial {
  double youngs_modulus_MPa = 193000.0;
  double poisson_ratio = 0.29;
  double density_g_per_mm3 = 8.0e-3;  // 8 g/cm^3

  double shear_modulus_MPa() const { return youngs_modulus_MPa / (2.0 * (1.0 + poisson_ratio)); }
  double lame_lambda_MPa() const {
    return youngs_modulus_MPa * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio));
  }
  // InputError naming the field for anything unphysical (E <= 0, nu outside (-1, 0.5), density <= 0).
  void validate(const std::string& where = "needle material") const;
};

}  // namespace needle
