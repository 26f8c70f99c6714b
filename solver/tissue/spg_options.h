#pragma once
// The numerical choices of the SPG tissue, each a parameter whose error is measured (docs/solver.md).
#include <string>

#include "solver/tissue/kernel_supports.h"

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

// Which particle strain the bond criterion averages over a pair:
//  - effective_strain: eps_p + the equivalent elastic log strain (the total effective strain; the paper:
//    "two adjacent SPG particles separate when the average effective tensile strain exceeds 1.84", the
//    rupture strain of its tensile test). A bond also fails when its own log stretch ln(l / L) exceeds
//    the same strain: the elastic part unloads when a crack opens, and a bond at the edge of a support
//    carries too little to keep its particles strained, so without this a cut never fully separates;
//  - plastic_strain: eps_p alone (LS-DYNA's SPG FS). With this card's large yield strain (1.44 at
//    E = 0.665 MPa) a bond would need ~3.3 total strain: in the insertion nothing breaks.
enum class FailureMeasure { effective_strain, plastic_strain };

FailureMeasure failure_measure_from_name(const std::string& name);  // "effective", "plastic"
std::string failure_measure_name(FailureMeasure m);

struct BondFailure {
  FailureMeasure measure = FailureMeasure::effective_strain;
  double strain = 1.84;          // a bond breaks when the pair's mean strain (of `measure`) exceeds this
  double stretch_ratio = 0.0;    // and/or when current / reference length exceeds this (0: off)
  bool enabled = true;
};

struct SpgOptions {
  double dilation = 1.8;  // support radius / particle spacing
  // sphere: radius dilation x the largest neighbouring interval (the reference); ellipsoid: dilation x the
  // interval along each axis (kernel_supports.h). The same on a uniform lattice.
  SupportShape support = SupportShape::sphere;
  KernelUpdate kernel_update = KernelUpdate::lagrangian;
  int kernel_update_interval_steps = 50;
  Stabilization stabilization = Stabilization::penalty;
  double stabilization_coefficient = 0.1;
  int smoothing_interval_steps = 10;  // for the filter
  BondFailure bond_failure;
  // A particle on a crack face (some of its bonds broken) whose volume ratio det F falls below this stops
  // being an integration point and moves on as a free particle (it keeps its mass and its contact). Its
  // one-sided support no longer measures the material's deformation: squeezed past the needle's tip it
  // reached det F 0.05 and set the whole tissue's time step (about 6x smaller). Checked at every force
  // evaluation and where a break rebuilds a row (a rebuilt support can measure a collapsed volume at once:
  // in SB at 28.8 mm one collapsed the step to 1e-4 of the first). Intact material is never detached;
  // below det F 1e-3 it is a blow-up. 0: only collapsed supports detach.
  double crack_face_min_volume_ratio = 0.25;
  double cfl = 0.5;  // time step = cfl x the smallest (current spacing / wave speed)

  void validate() const;  // InputError naming the bad field
};

KernelUpdate kernel_update_from_name(const std::string& name);
std::string kernel_update_name(KernelUpdate k);
Stabilization stabilization_from_name(const std::string& name);
std::string stabilization_name(Stabilization s);

}  // namespace needle
