#pragma once
// The SPG tissue: particles with RK shape functions, direct nodal integration, displacement-smoothing
// stabilization, MAT_018-style plasticity and bond failure. It computes forces from positions; the
// integrator (explicit_dynamics.h) advances it.
//
// Kinematics: F_i = sum_j x_j (x) grad Psi_j(X_i) over the kernel's reference X. Stress: Cauchy,
// updated from the relative deformation gradient F_n+1 F_n^-1 of the step (tissue_material.h). Force on particle j:
//   f_j = - sum_i V_i P_i grad Psi_j(X_i) + stabilization,   P = J sigma F^-T (first Piola-Kirchhoff),
// gathered through the transposed shape functions, so results do not depend on the thread count (the gather and the
// multi-rate levels: spg_rate_levels.cpp; the bonds breaking: spg_bond_failure.cpp; the stable step: spg_stable_step.cpp).
#include <Eigen/Dense>
#include <cstdint>
#include <limits>
#include <vector>

#include "mesher/particle_lattice.h"
#include "solver/tissue/bond_network.h"
#include "solver/tissue/kernel_supports.h"
#include "solver/tissue/rk_shape_functions.h"
#include "solver/tissue/spg_options.h"
#include "solver/tissue/tissue_material.h"

namespace needle {

using Vec3d = Eigen::Vector3d;
using Mat3d = Eigen::Matrix3d;

// Particle fields, one entry per particle (structure of arrays).
struct TissueParticles {
  std::vector<Vec3d> reference_mm;        // kernel reference positions X (reset by kernel re-initialisation)
  std::vector<Vec3d> initial_mm;          // positions at t = 0 (displacement output)
  std::vector<Vec3d> position_mm;
  std::vector<Vec3d> velocity_mm_per_ms;
  std::vector<Vec3d> force_N;             // internal + stabilization force of the last evaluation
  std::vector<double> mass_g;
  std::vector<double> reference_volume_mm3;
  std::vector<double> spacing_mm;
  KernelSupports supports;                // the kernel's supports in the reference (kernel_supports.h)
  std::vector<std::uint8_t> flags;        // ParticleFlag bits
  std::vector<Mat3d> deformation_gradient;  // relative to the kernel reference
  std::vector<Mat3d> stress_MPa;            // Cauchy
  std::vector<Mat3d> elastic_left_cauchy_green;  // b_e of the material (see tissue_material.h)
  std::vector<double> plastic_strain;
  std::vector<Mat3d> relaxed_stress_MPa;    // the Maxwell branch's q (empty unless the material is viscoelastic)
  std::vector<Mat3d> elastic_deviator_MPa;  // s_e of the last update (empty unless viscoelastic)
  std::vector<double> effective_strain;   // eps_p + equivalent elastic log strain (StressUpdate)
  std::vector<double> defect_mm;          // |g_i|, the smoothing defect (zero-energy-mode indicator)
  std::int64_t size() const { return static_cast<std::int64_t>(position_mm.size()); }
};

struct ForceReport {
  std::int64_t bonds_broken_now = 0;
  std::int64_t rate_factor_capped = 0;  // evaluations where the rate factor hit its cap
  std::int64_t particles_detached_now = 0;  // crack-face particles whose support collapsed (now free)
};

class SpgTissue {
 public:
  // InputError for a bad material, bad options, or particles that cannot carry shape functions.
  SpgTissue(const ParticleSet& particles, const TissueMaterial& material, const SpgOptions& options);

  // Forces at the current positions; dt_ms is the increment since the last call (0: first call, no
  // stress update). Then breaks the bonds that reached the failure criterion and rebuilds their rows.
  // SolverError on an inverted or non-finite particle.
  ForceReport compute_forces(double dt_ms);
  // compute_forces(dt_ms)'s first stage (deformation gradient, stress update, V P) done ahead, e.g. beside the
  // needle's solve, for the particles whose row's centres all stay where they are until compute_forces: those
  // `still` flags (one per particle) name. compute_forces(dt_ms) then does the others and the rest; the result
  // is the one of a single call, bit for bit. Returns how many points it updated. Until compute_forces, a still
  // particle must not move: check_may_move throws a SolverError for one that is about to.
  std::int64_t update_points_ahead(double dt_ms, const std::vector<std::uint8_t>& still);
  void check_may_move(std::int64_t i) const;

  // Breaks the given bonds (indices into bonds(); already broken ones are skipped) whatever the strains
  // say, e.g. where the needle's body separates their particles (needle_bond_cut.h), and rebuilds their
  // rows as break_bonds does. Returns how many it broke; they count in bonds().broken_count and cut_count.
  std::int64_t cut_bonds(const std::vector<std::int64_t>& bond_indices);

  // The smallest current spacing over the dilatational wave speed (with stabilization stiffness), x cfl.
  double stable_time_step_ms() const;
  // Each particle's own stable step, the same estimate with its own current support length and its own
  // strain (infinite for a detached particle, which no force holds); their minimum is at least the above.
  // Where a bound shows a particle's step is known_above_ms or more, that bound is given instead.
  void particle_time_steps_ms(std::vector<double>& dt_ms, double known_above_ms = std::numeric_limits<double>::infinity()) const;

  // Called by the integrator once per step (counts steps for the filter and the kernel update).
  void end_of_step();

  // Multi-rate (asynchronous) stepping, tissue_rate_levels.h: particle i of level k may take 2^k steps of
  // compute_forces' dt between its stress updates. A point (a particle as integration point) takes the level of
  // the fastest particle in its row and is updated every 2^level calls of compute_forces (dt > 0), counted from
  // this call; its forces on its row then count 2^level times, as the impulse of its whole period (an
  // asynchronous variational integrator: each point's forces sum to zero, so momentum is kept exactly). Between
  // its updates a point adds nothing: force_N is then the impulse-weighted force, not the force. Call only when
  // every point has just been updated (after construction, or when the last cycle is complete:
  // rate_cycle_complete); it recomputes force_N with the new weights for the step that starts now. An empty
  // vector returns to one rate.
  void set_rate_levels(const std::vector<std::uint8_t>& particle_level);
  bool multirate() const { return !point_level_.empty(); }
  // Whether every point was updated at the last compute_forces (always true at one rate).
  bool rate_cycle_complete() const;
  const std::vector<std::uint8_t>& point_levels() const { return point_level_; }

  double stabilization_energy_mJ() const;
  std::int64_t valid_integration_points() const;
  // Whether particle i is still an integration point (false once detached: a free mass point).
  bool is_integration_point(std::int64_t i) const { return rk_.valid[static_cast<size_t>(i)] != 0; }

  TissueParticles& particles() { return p_; }
  const TissueParticles& particles() const { return p_; }
  const TissueMaterial& material() const { return material_; }
  const SpgOptions& options() const { return options_; }
  const RkShapeFunctions& shape_functions() const { return rk_; }
  const BondNetwork& bonds() const { return bonds_; }

 private:
  void build_kernel();
  void update_stable_lengths();
  void update_shortest_bonds();  // each particle's shortest bond in the reference configuration
  void apply_filter();
  void reinitialize_kernel();
  std::int64_t break_bonds();
  // Marks the bonds listed in breaking, in increasing order with their kind (1: cut, 2: dead, no live row
  // changes), broken and rebuilds the rows of their particles; the count of those newly broken.
  std::int64_t separate(const std::vector<std::pair<std::int64_t, std::uint8_t>>& breaking);
  // Point s's deformation gradient, stress update, V P and smoothing defect; its status flags.
  void update_point(size_t s, double dt_ms);
  // Whether a crack-face particle's support still measures a volume (SpgOptions::crack_face_min_volume_ratio).
  bool crack_face_support_holds(const Mat3d& F, double J) const;
  // Particle s stops being an integration point: its row, smoothing defect and stress are cleared; it
  // moves on as a free mass point.
  void detach(size_t s);
  // An unloaded material at s: b_e = I and, if viscoelastic, no Maxwell stress (the particle stopped being
  // an integration point).
  void reset_material_state(size_t s);
  void refresh_reference_matrix();
  // Multi-rate: whether point s is updated at the rate_step-th compute_forces since the levels were set.
  bool point_due(size_t s, std::int64_t rate_step) const {
    return point_level_.empty() || rate_step % (std::int64_t{1} << point_level_[s]) == 0;
  }
  // The forces on particles [begin, end) from the points due at rate_step (every point: all_due), each weighted
  // by 2^its level (at one rate, the plain forces).
  void gather_forces(std::int64_t begin, std::int64_t end, std::int64_t rate_step, bool all_due);
  // Multi-rate: updates point s's stress to the tissue's current time if it lags (its row is about to change).
  void catch_up_point(size_t s);

  TissueParticles p_;
  TissueMaterial material_;
  SpgOptions options_;
  RkShapeFunctions rk_;
  BondNetwork bonds_;
  std::vector<double> stiffness_;  // kappa_i of the penalty
  std::vector<double> stable_length_mm_;  // min(spacing, nearest neighbour distance) in the kernel reference
  // The smallest principal stretch of F: bounds kept by compute_forces, the value itself (-1: not yet)
  // computed by min_stretch(s) for the particles a time step needs.
  void set_stretch_bounds(size_t s);
  double min_stretch(size_t s) const;
  mutable std::vector<double> min_stretch_;
  std::vector<double> stretch_lower_, stretch_upper_;
  std::vector<std::uint8_t> point_status_;  // scratch flags of compute_forces
  double ahead_dt_ms_ = -1;                  // the step update_points_ahead updated points for (-1: none pending)
  std::vector<std::uint8_t> ahead_, still_;  // the points it updated; the particles it was told stay
  Eigen::MatrixX3d reference_;            // #P by 3 copy of reference_mm for the shape-function builders
  std::vector<Vec3d> defect_;      // g_i
  std::vector<Mat3d> piola_volume_;  // V_i P_i
  std::int64_t steps_ = 0;
  std::vector<double> shortest_bond_mm_;  // per particle (infinite without bonds)
  std::vector<std::uint8_t> active_;      // break_bonds' scratch: particles whose bonds may break
  std::int64_t detached_on_rebuild_ = 0;  // crack-face particles separate() detached (counted into ForceReport)
  // Multi-rate state (empty at one rate): each point's level, each particle's fastest point in its column, the
  // compute_forces calls since the levels were set, the tissue's time and each point's last update.
  std::vector<std::uint8_t> point_level_, gather_level_;
  std::int64_t rate_step_ = 0;
  std::uint8_t max_point_level_ = 0;
  double time_ms_ = 0;
  std::vector<double> point_time_ms_;
};

}  // namespace needle
