#pragma once
// The Maxwell relaxation of the shear stress (TissueMaterial::viscoelastic, off in the paper's card): one branch
// whose stress q obeys dq/dt = (g s_e - q) / tau, applied after either law's update (tissue_material.h,
// MaterialPoint). One of the tissue's models update_stress dispatches to.
#include <Eigen/Dense>

#include "solver/tissue/tissue_material.h"

namespace needle {

// The branch over one increment with relative deformation gradient f: exact for s_e linear in time; q and the
// last s_e are carried with the increment's rotation. Sets after's relaxed stress and elastic deviator.
void maxwell_relax(const TissueMaterial& m, const Eigen::Matrix3d& f, double dt_ms, const Eigen::Matrix3d& elastic_deviator,
                   const MaterialPoint& before, MaterialPoint& after);

}  // namespace needle
