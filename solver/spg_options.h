#pragma once
// The numerical choices of the SPG tissue, each a parameter whose error is measured (docs/solver.md).
#include <string>

namespace needle {

// How the kernel follows the material: `lagrangian` keeps the reference supports (total Lagrangian);
// `reinitialized` makes the current configuration the new reference every kernel_update_interval_steps
// (updated kernel, for extreme deformation; bonds never form anew, so cut material does not heal).
enum class KernelUpdate { lagrangian, reinitialized };

// Removal of the zero-energy modes of direct nodal integration through displacement smoothing,
// with the RK interpolant itself as the smoother: the defect g_i = x_i - sum_j Psi_j(X_i) x_j vanishes
// for every affine motion (rigid or not), so it only sees the oscillating part of the displacement.
//  - penalty: adds the energy 1/2 sum_i kappa_i |g_i|^2 every step, kappa_i = coefficient (lambda+2mu) V_i / h_i^2;
//    conservative (energy and momentum exact), patch test untouched.
//  - filter:  every smoothing_interval_steps, replaces u and v by u - coefficient * g (the regularisation
//    of LS-DYNA's SMSTEP); dissipative on the oscillating part only.
//  - none:    plain nodal integration (shows the spurious modes; for tests).
enum class Stabilization { none, penalty, filter };

struct BondFailure {
  double plastic_strain = 1.84;  // a bond breaks when the pair's mean effective plastic strain exceeds this
  double stretch_ratio = 0.0;    // and/or when current / reference length exceeds this (0: off)
  bool enabled = true;
};

struct SpgOptions {
  double dilation = 1.8;  // support radius / particle spacing
  KernelUpdate kernel_update = KernelUpdate::lagrangian;
  int kernel_update_interval_steps = 50;
  Stabilization stabilization = Stabilization::penalty;
  double stabilization_coefficient = 0.1;
  int smoothing_interval_steps = 10;  // for the filter
  BondFailure bond_failure;
  double cfl = 0.5;  // time step = cfl x the smallest (current spacing / wave speed)

  void validate() const;  // InputError naming the bad field
};

KernelUpdate kernel_update_from_name(const std::string& name);
std::string kernel_update_name(KernelUpdate k);
Stabilization stabilization_from_name(const std::string& name);
std::string stabilization_name(Stabilization s);

}  // namespace needle
