#include "solver/tissue/spg_tissue.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <unordered_set>

#include "core/input_error.h"
#include "core/parallel.h"
#include "core/solver_error.h"

namespace needle {
namespace {

constexpr double kMinJacobian = 1e-3;  // a particle compressed below 1/1000 of its volume is a blow-up
enum : std::uint8_t { kCapped = 1, kFailed = 2, kDetached = 4 };  // a point's status after its update

Vec3d gather_defect(const RkShapeFunctions& rk, std::int64_t i, const std::vector<Vec3d>& field) {
  Vec3d smoothed = Vec3d::Zero();
  for (std::int64_t e = rk.offset[static_cast<size_t>(i)]; e < rk.offset[static_cast<size_t>(i + 1)]; ++e)
    smoothed += rk.psi[static_cast<size_t>(e)] * field[static_cast<size_t>(rk.centre[static_cast<size_t>(e)])];
  return field[static_cast<size_t>(i)] - smoothed;
}

Mat3d gather_gradient(const RkShapeFunctions& rk, std::int64_t i, const std::vector<Vec3d>& x) {
  Mat3d F = Mat3d::Zero();
  for (std::int64_t e = rk.offset[static_cast<size_t>(i)]; e < rk.offset[static_cast<size_t>(i + 1)]; ++e) {
    const Vec3& g = rk.grad[static_cast<size_t>(e)];
    F.noalias() += x[static_cast<size_t>(rk.centre[static_cast<size_t>(e)])] * Eigen::RowVector3d(g[0], g[1], g[2]);
  }
  return F;
}

// Both of the above in one pass over row i (each sum in the same order as alone, so the same bits).
void gather_defect_and_gradient(const RkShapeFunctions& rk, std::int64_t i, const std::vector<Vec3d>& x, Vec3d& defect, Mat3d& F) {
  Vec3d smoothed = Vec3d::Zero();
  F.setZero();
  for (std::int64_t e = rk.offset[static_cast<size_t>(i)]; e < rk.offset[static_cast<size_t>(i + 1)]; ++e) {
    const Vec3d& xc = x[static_cast<size_t>(rk.centre[static_cast<size_t>(e)])];
    smoothed += rk.psi[static_cast<size_t>(e)] * xc;
    const Vec3& g = rk.grad[static_cast<size_t>(e)];
    F.noalias() += xc * Eigen::RowVector3d(g[0], g[1], g[2]);
  }
  defect = x[static_cast<size_t>(i)] - smoothed;
}

}  // namespace

SpgTissue::SpgTissue(const ParticleSet& set, const TissueMaterial& material, const SpgOptions& options)
    : material_(material), options_(options) {
  material_.validate();
  options_.validate();
  const std::int64_t n = set.num_particles();
  NEEDLE_REQUIRE(n >= 4, "the tissue needs at least 4 particles");
  NEEDLE_REQUIRE(set.volume_mm3.size() == n && set.spacing_mm.size() == n && set.flags.size() == n,
                 "particle set fields have different lengths");
  NEEDLE_REQUIRE((set.spacing_mm.array() > 0).all() && set.spacing_mm.allFinite(), "particle spacing must be positive");
  NEEDLE_REQUIRE((set.volume_mm3.array() > 0).all() && set.volume_mm3.allFinite(), "particle volumes must be positive");
  NEEDLE_REQUIRE(set.x_mm.allFinite(), "particle positions must be finite");
  const double rho = material_.density_g_per_mm3();
  p_.reference_mm.resize(static_cast<size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) p_.reference_mm[static_cast<size_t>(i)] = set.x_mm.row(i).transpose();
  p_.initial_mm = p_.position_mm = p_.reference_mm;
  p_.velocity_mm_per_ms.assign(static_cast<size_t>(n), Vec3d::Zero());
  p_.force_N.assign(static_cast<size_t>(n), Vec3d::Zero());
  p_.reference_volume_mm3.assign(set.volume_mm3.data(), set.volume_mm3.data() + n);
  p_.spacing_mm.assign(set.spacing_mm.data(), set.spacing_mm.data() + n);
  p_.flags.assign(set.flags.data(), set.flags.data() + n);
  p_.mass_g.resize(static_cast<size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) p_.mass_g[static_cast<size_t>(i)] = rho * p_.reference_volume_mm3[static_cast<size_t>(i)];
  if (options_.support == SupportShape::sphere) {
    p_.supports = KernelSupports(Eigen::VectorXd(options_.dilation * set.spacing_mm));
  } else {
    // A set without per-axis intervals (not a lattice) gets its largest interval along every axis.
    const bool per_axis = set.axis_spacing_mm.rows() == n;
    NEEDLE_REQUIRE(!per_axis || ((set.axis_spacing_mm.array() > 0).all() && set.axis_spacing_mm.allFinite()),
                   "particle spacing along each axis must be positive");
    Eigen::MatrixX3d semi_axes(n, 3);
    for (std::int64_t i = 0; i < n; ++i)
      semi_axes.row(i) = options_.dilation * (per_axis ? Eigen::RowVector3d(set.axis_spacing_mm.row(i)) : Eigen::RowVector3d::Constant(set.spacing_mm[i]));
    p_.supports = KernelSupports::ellipsoids(semi_axes);
  }
  p_.deformation_gradient.assign(static_cast<size_t>(n), Mat3d::Identity());
  p_.stress_MPa.assign(static_cast<size_t>(n), Mat3d::Zero());
  p_.elastic_left_cauchy_green.assign(static_cast<size_t>(n), Mat3d::Identity());
  p_.plastic_strain.assign(static_cast<size_t>(n), 0.0);
  if (material_.viscoelastic()) {
    p_.relaxed_stress_MPa.assign(static_cast<size_t>(n), Mat3d::Zero());
    p_.elastic_deviator_MPa.assign(static_cast<size_t>(n), Mat3d::Zero());
  }
  p_.effective_strain.assign(static_cast<size_t>(n), 0.0);
  p_.defect_mm.assign(static_cast<size_t>(n), 0.0);
  defect_.assign(static_cast<size_t>(n), Vec3d::Zero());
  piola_volume_.assign(static_cast<size_t>(n), Mat3d::Zero());
  min_stretch_.assign(static_cast<size_t>(n), 1.0);
  stretch_lower_.assign(static_cast<size_t>(n), 1.0);
  stretch_upper_.assign(static_cast<size_t>(n), 1.0);
  point_status_.assign(static_cast<size_t>(n), 0);
  stiffness_.resize(static_cast<size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) {
    const double h = p_.spacing_mm[static_cast<size_t>(i)];
    stiffness_[static_cast<size_t>(i)] = options_.stabilization == Stabilization::penalty
        ? options_.stabilization_coefficient * material_.p_wave_modulus_MPa() * p_.reference_volume_mm3[static_cast<size_t>(i)] / (h * h)
        : 0.0;
  }
  build_kernel();
  const std::int64_t valid = valid_integration_points();
  NEEDLE_REQUIRE(valid == n, fmt::format("{} of {} particles have too few non-coplanar neighbours for linear RK shape functions "
                                         "at dilation {}: use a larger dilation or a thicker particle set", n - valid, n, options_.dilation));
}

void SpgTissue::refresh_reference_matrix() {
  reference_.resize(p_.size(), 3);
  for (std::int64_t i = 0; i < p_.size(); ++i) reference_.row(i) = p_.reference_mm[static_cast<size_t>(i)].transpose();
}

void SpgTissue::build_kernel() {
  refresh_reference_matrix();
  const Eigen::MatrixX3d& X = reference_;
  rk_ = build_rk_shape_functions(X, p_.supports);
  bonds_ = build_bond_network(rk_);
  update_stable_lengths();
  update_shortest_bonds();
}

void SpgTissue::update_stable_lengths() {
  // Irregular sets put neighbours closer than the nominal spacing; the time step must see that.
  stable_length_mm_.resize(static_cast<size_t>(p_.size()));
  for (std::int64_t i = 0; i < p_.size(); ++i) {
    double length = p_.spacing_mm[static_cast<size_t>(i)];
    for (std::int64_t e = rk_.offset[static_cast<size_t>(i)]; e < rk_.offset[static_cast<size_t>(i + 1)]; ++e) {
      const std::int32_t j = rk_.centre[static_cast<size_t>(e)];
      if (j != i) length = std::min(length, (p_.reference_mm[static_cast<size_t>(j)] - p_.reference_mm[static_cast<size_t>(i)]).norm());
    }
    stable_length_mm_[static_cast<size_t>(i)] = length;
  }
}

std::int64_t SpgTissue::valid_integration_points() const {
  return std::count(rk_.valid.begin(), rk_.valid.end(), std::uint8_t{1});
}

void SpgTissue::update_point(size_t s, double dt_ms) {
  std::vector<std::uint8_t>& status = point_status_;
  const bool viscoelastic = material_.viscoelastic();
  const std::int64_t i = static_cast<std::int64_t>(s);
  if (!rk_.valid[s]) {
    defect_[s].setZero();
    p_.defect_mm[s] = 0;
    piola_volume_[s].setZero();
    p_.stress_MPa[s].setZero();
    reset_material_state(s);
    p_.effective_strain[s] = p_.plastic_strain[s];
    return;
  }
  Mat3d F;
  gather_defect_and_gradient(rk_, i, p_.position_mm, defect_[s], F);
  p_.defect_mm[s] = defect_[s].norm();
  const double J = F.determinant();
  const bool collapsed = !(J > kMinJacobian) || !F.allFinite();
  if (!crack_face_support_holds(F, J)) {
    // A particle on a crack face (some bonds cut) whose remaining support collapses stops being an
    // integration point: it keeps its mass and moves on as a free particle. Intact material that
    // inverts is a blow-up; intact material merely compressed that far stays.
    bool on_crack = false;
    for (std::int64_t e = rk_.offset[s]; e < rk_.offset[s + 1] && !on_crack; ++e) on_crack = rk_.cut[static_cast<size_t>(e)];
    if (collapsed && !on_crack) {
      status[s] = kFailed;
      return;
    }
    if (on_crack) {
      status[s] = kDetached;  // detach() below, serially (it counts)
      return;
    }
  }
  if (dt_ms > 0) {
    MaterialPoint point;
    point.elastic_left_cauchy_green = p_.elastic_left_cauchy_green[s];
    point.plastic_strain = p_.plastic_strain[s];
    if (viscoelastic) {
      point.relaxed_stress_MPa = p_.relaxed_stress_MPa[s];
      point.elastic_deviator_MPa = p_.elastic_deviator_MPa[s];
    }
    StressUpdate u = update_stress(material_, point, F * p_.deformation_gradient[s].inverse(), dt_ms);
    if (p_.flags[s] & kParticleCrushed) keep_pressure_only(u);
    p_.stress_MPa[s] = u.cauchy_stress_MPa;
    p_.elastic_left_cauchy_green[s] = u.state.elastic_left_cauchy_green;
    p_.plastic_strain[s] = u.state.plastic_strain;
    if (viscoelastic) {
      p_.relaxed_stress_MPa[s] = u.state.relaxed_stress_MPa;
      p_.elastic_deviator_MPa[s] = u.state.elastic_deviator_MPa;
    }
    p_.effective_strain[s] = u.effective_strain;
    if (u.rate_factor_capped) status[s] = kCapped;
  }
  p_.deformation_gradient[s] = F;
  set_stretch_bounds(s);
  piola_volume_[s] = p_.reference_volume_mm3[s] * J * p_.stress_MPa[s] * F.inverse().transpose();
}

std::int64_t SpgTissue::update_points_ahead(double dt_ms, const std::vector<std::uint8_t>& still) {
  const std::int64_t n = p_.size();
  NEEDLE_REQUIRE(still.size() == static_cast<size_t>(n), "update_points_ahead: one flag per particle");
  NEEDLE_REQUIRE(ahead_dt_ms_ < 0, "update_points_ahead: the points updated ahead were not used by compute_forces yet");
  std::fill(point_status_.begin(), point_status_.end(), std::uint8_t{0});
  ahead_.assign(static_cast<size_t>(n), 0);
  still_ = still;
  ahead_dt_ms_ = dt_ms;
  const std::int64_t rate_step = rate_step_ + 1;
  const double now_ms = time_ms_ + dt_ms;
  parallel_for(n, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) {
      const size_t s = static_cast<size_t>(i);
      if (!still[s] || !point_due(s, rate_step)) continue;
      bool row_still = true;
      for (std::int64_t e = rk_.offset[s]; e < rk_.offset[s + 1] && row_still; ++e) row_still = still[static_cast<size_t>(rk_.centre[static_cast<size_t>(e)])];
      if (!row_still) continue;
      if (multirate()) {
        update_point(s, now_ms - point_time_ms_[s]);
        point_time_ms_[s] = now_ms;
      } else {
        update_point(s, dt_ms);
      }
      ahead_[s] = 1;
    }
  });
  return std::count(ahead_.begin(), ahead_.end(), std::uint8_t{1});
}

void SpgTissue::check_may_move(std::int64_t i) const {
  if (ahead_dt_ms_ >= 0 && still_[static_cast<size_t>(i)])
    throw SolverError(fmt::format("particle {} near x = ({:.3f}, {:.3f}, {:.3f}) mm moves within a step in which the stresses around it were "
                                  "updated ahead, as if it stayed (the coupling's margin around the needle was too small: "
                                  "solver.tissue_ahead_margin_mm, or solver.tissue_beside_needle false)",
                                  i, p_.position_mm[static_cast<size_t>(i)].x(), p_.position_mm[static_cast<size_t>(i)].y(),
                                  p_.position_mm[static_cast<size_t>(i)].z()));
}

ForceReport SpgTissue::compute_forces(double dt_ms) {
  ForceReport report;
  const std::int64_t n = p_.size();
  std::vector<std::uint8_t>& status = point_status_;
  // 1. Deformation gradient, stress update, V P and the smoothing defect at every integration point (but those
  // update_points_ahead did).
  const bool ahead = ahead_dt_ms_ >= 0;
  NEEDLE_REQUIRE(!ahead || ahead_dt_ms_ == dt_ms, "compute_forces: the points updated ahead were updated for another step");
  NEEDLE_REQUIRE(!multirate() || dt_ms > 0, "compute_forces: a multi-rate tissue steps forward (dt > 0)");
  if (!ahead) std::fill(status.begin(), status.end(), std::uint8_t{0});
  time_ms_ += dt_ms;
  const std::int64_t rate_step = multirate() ? ++rate_step_ : 0;
  if (multirate()) {
    parallel_for(n, [&](std::int64_t begin, std::int64_t end) {
      for (std::int64_t i = begin; i < end; ++i) {
        const size_t s = static_cast<size_t>(i);
        if (!point_due(s, rate_step) || (ahead && ahead_[s])) continue;
        update_point(s, time_ms_ - point_time_ms_[s]);
        point_time_ms_[s] = time_ms_;
      }
    });
  } else {
    parallel_for(n, [&](std::int64_t begin, std::int64_t end) {
      for (std::int64_t i = begin; i < end; ++i)
        if (!ahead || !ahead_[static_cast<size_t>(i)]) update_point(static_cast<size_t>(i), dt_ms);
    });
  }
  ahead_dt_ms_ = -1;
  for (std::int64_t i = 0; i < n; ++i)
    if (status[static_cast<size_t>(i)] & kFailed)
      throw SolverError(fmt::format("particle {} inverted or blew up (det F <= {} or not finite) near x = ({:.3f}, {:.3f}, {:.3f}) mm",
                                    i, kMinJacobian, p_.position_mm[static_cast<size_t>(i)].x(),
                                    p_.position_mm[static_cast<size_t>(i)].y(), p_.position_mm[static_cast<size_t>(i)].z()));
  report.rate_factor_capped = std::count(status.begin(), status.end(), std::uint8_t{kCapped});
  for (std::int64_t i = 0; i < n; ++i)
    if (status[static_cast<size_t>(i)] & kDetached) {
      detach(static_cast<size_t>(i));
      ++report.particles_detached_now;
    }

  // 2. Forces, gathered per particle through the transpose.
  parallel_for(n, [&](std::int64_t begin, std::int64_t end) { gather_forces(begin, end, rate_step, false); });
  if (options_.bond_failure.enabled) report.bonds_broken_now = break_bonds();
  report.particles_detached_now += detached_on_rebuild_;  // by this evaluation's breaks and cut_bonds since the last
  detached_on_rebuild_ = 0;
  return report;
}

void SpgTissue::catch_up_point(size_t s) {
  if (!multirate() || point_time_ms_[s] == time_ms_) return;
  point_status_[s] = 0;
  update_point(s, time_ms_ - point_time_ms_[s]);
  point_time_ms_[s] = time_ms_;
  if (point_status_[s] & kFailed)
    throw SolverError(fmt::format("particle {} inverted or blew up (det F <= {} or not finite) near x = ({:.3f}, {:.3f}, {:.3f}) mm", s,
                                  kMinJacobian, p_.position_mm[s].x(), p_.position_mm[s].y(), p_.position_mm[s].z()));
  if (point_status_[s] & kDetached) {
    detach(s);
    ++detached_on_rebuild_;
  }
  point_status_[s] = 0;
}

std::int64_t SpgTissue::separate(const std::vector<std::pair<std::int64_t, std::uint8_t>>& breaking) {
  NEEDLE_REQUIRE(ahead_dt_ms_ < 0, "bonds break between update_points_ahead and compute_forces");
  std::vector<std::int64_t> rows;
  for (const auto& [b, kind] : breaking) {
    bonds_.mark_broken(b);
    const Bond& bond = bonds_.bonds[static_cast<size_t>(b)];
    if (bond.entry_ij >= 0) rk_.cut[static_cast<size_t>(bond.entry_ij)] = 1;
    if (bond.entry_ji >= 0) rk_.cut[static_cast<size_t>(bond.entry_ji)] = 1;
    if (kind == 2) continue;  // dead: no row of a live integration point changes
    rows.push_back(bond.i);
    rows.push_back(bond.j);
  }
  const std::int64_t count = static_cast<std::int64_t>(breaking.size());
  bonds_.broken_count += count;
  if (rows.empty()) return count;
  std::sort(rows.begin(), rows.end());
  rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
  // A detached particle stays detached: its row is not rebuilt (that would revive it with a support
  // that already collapsed once).
  rows.erase(std::remove_if(rows.begin(), rows.end(), [&](std::int64_t i) { return !rk_.valid[static_cast<size_t>(i)]; }), rows.end());
  if (rows.empty()) return count;
  // Multi-rate: a point between its updates first takes the motion since its last one with its old row.
  for (std::int64_t i : rows) catch_up_point(static_cast<size_t>(i));
  rows.erase(std::remove_if(rows.begin(), rows.end(), [&](std::int64_t i) { return !rk_.valid[static_cast<size_t>(i)]; }), rows.end());
  if (rows.empty()) return count;
  rebuild_rk_rows(rk_, rows, reference_, reference_, p_.supports);
  // The next stress increment must see only motion, not the change of shape functions: restart F there.
  // Every rebuilt row is on a crack face now: where its new support measures a collapsed volume it
  // detaches at once (as compute_forces would at the next evaluation), before its F can set the step.
  for (std::int64_t i : rows) {
    const size_t s = static_cast<size_t>(i);
    if (rk_.valid[s]) {
      const Mat3d F = gather_gradient(rk_, i, p_.position_mm);
      if (crack_face_support_holds(F, F.determinant())) {
        p_.deformation_gradient[s] = F;
        set_stretch_bounds(s);
        continue;
      }
      ++detached_on_rebuild_;
    }
    detach(s);
  }
  return count;
}

bool SpgTissue::crack_face_support_holds(const Mat3d& F, double J) const {
  return F.allFinite() && J > kMinJacobian && J >= options_.crack_face_min_volume_ratio;
}

void SpgTissue::detach(size_t s) {
  rk_.valid[s] = 0;
  for (std::int64_t e = rk_.offset[s]; e < rk_.offset[s + 1]; ++e) set_rk_entry(rk_, e, 0, {0, 0, 0});
  defect_[s].setZero();
  piola_volume_[s].setZero();
  p_.stress_MPa[s].setZero();
  reset_material_state(s);
  p_.effective_strain[s] = p_.plastic_strain[s];
}

void SpgTissue::reset_material_state(size_t s) {
  p_.elastic_left_cauchy_green[s].setIdentity();
  if (material_.viscoelastic()) {
    p_.relaxed_stress_MPa[s].setZero();
    p_.elastic_deviator_MPa[s].setZero();
  }
}

void SpgTissue::end_of_step() {
  ++steps_;
  if (options_.stabilization == Stabilization::filter && steps_ % options_.smoothing_interval_steps == 0) apply_filter();
  if (options_.kernel_update == KernelUpdate::reinitialized && steps_ % options_.kernel_update_interval_steps == 0)
    reinitialize_kernel();
}

void SpgTissue::apply_filter() {
  // u <- u - beta g(u), v <- v - beta g(v); constrained particles are reset by the integrator's BCs.
  const double beta = options_.stabilization_coefficient;
  const std::int64_t n = p_.size();
  std::vector<Vec3d> dx(static_cast<size_t>(n)), dv(static_cast<size_t>(n));
  parallel_for(n, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) {
      const size_t s = static_cast<size_t>(i);
      dx[s] = rk_.valid[s] ? Vec3d(-beta * gather_defect(rk_, i, p_.position_mm)) : Vec3d::Zero();
      dv[s] = rk_.valid[s] ? Vec3d(-beta * gather_defect(rk_, i, p_.velocity_mm_per_ms)) : Vec3d::Zero();
    }
  });
  for (std::int64_t i = 0; i < n; ++i) {
    if (p_.flags[static_cast<size_t>(i)] & kParticleFixed) continue;
    p_.position_mm[static_cast<size_t>(i)] += dx[static_cast<size_t>(i)];
    p_.velocity_mm_per_ms[static_cast<size_t>(i)] += dv[static_cast<size_t>(i)];
  }
}

void SpgTissue::reinitialize_kernel() {
  // The current configuration becomes the reference; intact bonds only (no healing across cracks). Multi-rate:
  // the points between their updates first take the motion since their last one.
  for (size_t s = 0; s < point_time_ms_.size(); ++s) catch_up_point(s);
  std::unordered_set<std::uint64_t> intact;
  intact.reserve(bonds_.bonds.size() * 2);
  auto key = [](std::int32_t a, std::int32_t b) {
    return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b));
  };
  for (const Bond& b : bonds_.bonds)
    if (!b.broken) intact.insert(key(b.i, b.j));
  const std::int64_t n = p_.size();
  for (std::int64_t i = 0; i < n; ++i) {
    const size_t s = static_cast<size_t>(i);
    if (rk_.valid[s]) p_.reference_volume_mm3[s] *= p_.deformation_gradient[s].determinant();
    p_.reference_mm[s] = p_.position_mm[s];
    p_.deformation_gradient[s].setIdentity();
    min_stretch_[s] = stretch_lower_[s] = stretch_upper_[s] = 1.0;
  }
  refresh_reference_matrix();
  const Eigen::MatrixX3d& X = reference_;
  NeighbourLists all = find_covering_centres(X, X, p_.supports);
  NeighbourLists kept;
  kept.offset.assign(all.offset.size(), 0);
  for (std::int64_t i = 0; i < n; ++i) {
    for (std::int64_t e = all.offset[static_cast<size_t>(i)]; e < all.offset[static_cast<size_t>(i + 1)]; ++e) {
      const std::int32_t j = all.index[static_cast<size_t>(e)];
      if (j == i || intact.count(key(static_cast<std::int32_t>(i), j))) kept.index.push_back(j);
    }
    kept.offset[static_cast<size_t>(i + 1)] = static_cast<std::int64_t>(kept.index.size());
  }
  const std::int64_t broken_before = bonds_.broken_count;
  rk_ = build_rk_shape_functions(kept, X, p_.supports);
  bonds_ = build_bond_network(rk_);
  update_stable_lengths();
  update_shortest_bonds();
  bonds_.broken_count = broken_before;
  for (std::int64_t i = 0; i < n; ++i)
    if (!rk_.valid[static_cast<size_t>(i)]) {
      p_.stress_MPa[static_cast<size_t>(i)].setZero();
      reset_material_state(static_cast<size_t>(i));
    }
}

double SpgTissue::stabilization_energy_mJ() const {
  if (options_.stabilization != Stabilization::penalty) return 0.0;
  double energy = 0;
  for (std::int64_t i = 0; i < p_.size(); ++i)
    energy += 0.5 * stiffness_[static_cast<size_t>(i)] * defect_[static_cast<size_t>(i)].squaredNorm();
  return energy;
}

}  // namespace needle
