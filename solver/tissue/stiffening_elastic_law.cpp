#include "solver/tissue/stiffening_elastic_law.h"

#include <algorithm>
#include <cmath>

namespace needle {

double TissueMaterial::equivalent_stress_MPa(double eps) const {
  return 3 * shear_modulus_MPa() * eps + k_MPa * std::pow(std::max(eps, 0.0), n);
}

double stiffening_elastic_secant_shear_modulus_MPa(const TissueMaterial& m, double eps_eq) {
  return eps_eq > 0 ? m.equivalent_stress_MPa(eps_eq) / (3 * eps_eq) : m.shear_modulus_MPa();
}

Eigen::Vector3d stiffening_elastic_deviatoric_stress(const TissueMaterial& m, const Eigen::Vector3d& h_dev, double eps_eq) {
  return 2 * stiffening_elastic_secant_shear_modulus_MPa(m, eps_eq) * h_dev;
}

double stiffening_elastic_uniaxial_true_stress_MPa(const TissueMaterial& m, double true_strain) {
  // Uniaxial stress: h = (e, -t, -t) with sigma = q(2/3 (e + t)) and sigma / 3 = K (e - 2 t); solve the
  // lateral contraction t by bisection (q rises with t, the volumetric pressure falls).
  const double e = std::abs(true_strain), K = m.bulk_modulus_MPa();
  double lo = -e, hi = e;
  for (int it = 0; it < 200; ++it) {
    const double t = 0.5 * (lo + hi);
    if (m.equivalent_stress_MPa(2.0 / 3.0 * (e + t)) > 3 * K * (e - 2 * t)) hi = t; else lo = t;
  }
  const double stress = 3 * K * (e - lo - hi);  // 3 K (e - 2 t) at t = (lo + hi) / 2
  return true_strain < 0 ? -stress : stress;
}

}  // namespace needle
