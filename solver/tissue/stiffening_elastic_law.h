#pragma once
// The stiffening elastic law (TissueLaw::stiffening_elastic): hyperelastic in the Hencky strain with the
// equivalent stress q(eps) = 3 G eps + k eps^n, the paper's measured power law on top of the small-strain
// modulus; no plasticity, no rate law (tissue_material.h). One of the tissue laws update_stress dispatches to.
#include <Eigen/Dense>

#include "solver/tissue/tissue_material.h"

namespace needle {

// The deviatoric principal Cauchy stress at the deviatoric log strain h_dev of equivalent strain eps_eq:
// 2 mu_s h_dev with the secant shear modulus mu_s = q(eps) / (3 eps) (G at eps = 0).
Eigen::Vector3d stiffening_elastic_deviatoric_stress(const TissueMaterial& m, const Eigen::Vector3d& h_dev, double eps_eq);
// The secant shear modulus mu_s = q(eps) / (3 eps) at equivalent strain eps (G at eps = 0).
double stiffening_elastic_secant_shear_modulus_MPa(const TissueMaterial& m, double eps_eq);

// The closed-form uniaxial curve (tissue_material.h: uniaxial_true_stress_MPa) of the law.
double stiffening_elastic_uniaxial_true_stress_MPa(const TissueMaterial& m, double true_strain);

}  // namespace needle
