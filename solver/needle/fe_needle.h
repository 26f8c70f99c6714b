#pragma once
// The needle as Lagrangian finite elements on the mesher's T4 or T10 mesh.
//
// Kinematics are total Lagrangian: at every quadrature point F = I + sum_a u_a (x) dN_a/dX, Green
// strain E = (F^T F - I)/2, Saint Venant-Kirchhoff S = lambda tr(E) I + 2 mu E, first Piola P = F S,
// nodal force f_a = - sum_q w_q P dN_a/dX. Rigid rotations of any size give zero force; for the
// small strains of steel this is linear elasticity. Strain energy W = lambda/2 tr(E)^2 + mu E:E.
// The mass is lumped (tet_element.h). Element forces are computed in parallel and gathered per node,
// so results do not depend on the thread count.
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <vector>

#include "mesher/tet_mesh.h"
#include "solver/needle/needle_material.h"

namespace needle {

struct ElementStresses {
  Eigen::VectorXd von_mises_MPa;    // per element, mean over its quadrature points
  Eigen::MatrixXd cauchy_MPa;       // per element: xx yy zz xy yz zx
};

class FeNeedle {
 public:
  // mass_scaling_dt_ms > 0 adds mass to every element whose own stable step is below it, so that no
  // element limits the step below that value (selective mass scaling, a speed-for-accuracy trade; the
  // added mass is reported). InputError for a bad material or a mesh with inverted elements.
  FeNeedle(TetMesh mesh, const NeedleMaterial& material, double mass_scaling_dt_ms = 0.0);

  const TetMesh& mesh() const { return mesh_; }
  const NeedleMaterial& material() const { return material_; }
  int num_nodes() const { return mesh_.num_nodes(); }
  int num_elements() const { return mesh_.num_tets(); }
  const Eigen::VectorXd& nodal_mass_g() const { return nodal_mass_; }
  double physical_mass_g() const { return physical_mass_; }
  double added_mass_g() const { return nodal_mass_.sum() - physical_mass_; }
  double volume_mm3() const { return physical_mass_ / material_.density_g_per_mm3; }
  int mass_scaled_elements() const { return mass_scaled_elements_; }

  // Largest stable central-difference step with the (possibly scaled) lumped masses: min over
  // elements of 2 / sqrt(lambda_max(M_e^-1 K_e)), an upper bound on the global eigenvalue; multiply by
  // a Courant factor < 1 before use. The smallest unscaled element step is reported separately.
  double stable_time_step_ms() const { return stable_dt_ms_; }
  double unscaled_time_step_ms() const { return unscaled_dt_ms_; }

  // Internal nodal forces (N, -dW/dx) at positions x_mm (#nodes x 3); returns the strain energy (mJ).
  double internal_forces(const Eigen::MatrixX3d& x_mm, Eigen::MatrixX3d& force_N) const;

  // Stiffness at the reference configuration (linear elasticity), 3 #nodes square, dof = 3 node + axis.
  Eigen::SparseMatrix<double> stiffness_matrix() const;

  ElementStresses element_stresses(const Eigen::MatrixX3d& x_mm) const;

 private:
  const double* gradients(int element, int q) const { return &gradients_[(static_cast<size_t>(element) * qp_ + q) * npe_ * 3]; }
  double weight(int element, int q) const { return weights_[static_cast<size_t>(element) * qp_ + q]; }
  Eigen::MatrixXd element_stiffness(int element) const;

  TetMesh mesh_;
  NeedleMaterial material_;
  int npe_ = 0, qp_ = 0;
  std::vector<double> gradients_;  // per element and quadrature point: dN/dX, npe x 3 row-major
  std::vector<double> weights_;    // per element and quadrature point: w det J (mm^3)
  Eigen::VectorXd nodal_mass_;
  double physical_mass_ = 0, stable_dt_ms_ = 0, unscaled_dt_ms_ = 0;
  int mass_scaled_elements_ = 0;
  std::vector<int> node_offsets_, node_slots_;  // CSR: node -> slots (element * npe + local)
  mutable std::vector<double> element_forces_;  // per slot, 3 values
  mutable std::vector<double> element_energy_;
};

}  // namespace needle
