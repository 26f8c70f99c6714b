#include "solver/needle/implicit_needle.h"

#include <Eigen/CholmodSupport>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/input_error.h"
#include "core/solver_error.h"

namespace needle {

struct ImplicitNeedle::Factor {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>> llt;
  std::unordered_map<int, Eigen::VectorXd> columns;  // A^-1 e_dof by dof, for the cannula's nodes
};

ImplicitNeedle::ImplicitNeedle(const FeNeedle& needle, NeedleSupports supports, const std::optional<CannulaOptions>& cannula,
                               const NeedleDynamicsOptions& options)
    : needle_(needle), supports_(std::move(supports)), options_(options) {
  supports_.profile.validate();
  NEEDLE_REQUIRE(supports_.clamped.empty(), "the implicit needle is driven at its base; clamped supports need the fe model");
  NEEDLE_REQUIRE(!supports_.driven.empty(), "the implicit needle needs driven base nodes");
  NEEDLE_REQUIRE(supports_.direction.allFinite() && supports_.direction.norm() > 0, "drive direction must be a non-zero vector");
  NEEDLE_REQUIRE(std::isfinite(options_.implicit_step_ms) && options_.implicit_step_ms > 0,
                 fmt::format("the implicit needle's step must be positive (got {} ms; scene key solver.implicit_needle_step_ms)", options_.implicit_step_ms));
  supports_.direction.normalize();
  step_ms_ = options_.implicit_step_ms;
  const int n = needle.num_nodes();
  mass_ = needle.nodal_mass_g();
  std::vector<std::uint8_t> held(3 * static_cast<size_t>(n), 0);
  for (int i : supports_.driven) {
    NEEDLE_REQUIRE(i >= 0 && i < n, fmt::format("driven node {} does not exist", i));
    for (int k = 0; k < 3; ++k) held[3 * static_cast<size_t>(i) + k] = 1;
  }
  for (int i : supports_.symmetry) {
    NEEDLE_REQUIRE(i >= 0 && i < n, fmt::format("symmetry node {} does not exist", i));
    held[3 * static_cast<size_t>(i) + 2] = 1;
  }
  std::vector<int> index(3 * static_cast<size_t>(n), -1);
  for (int d = 0; d < 3 * n; ++d)
    if (!held[static_cast<size_t>(d)]) {
      index[static_cast<size_t>(d)] = static_cast<int>(free_dof_.size());
      free_dof_.push_back(d);
    }
  K_ = needle.stiffness_matrix();
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(K_.nonZeros() / 2 + free_dof_.size()));
  for (int col = 0; col < K_.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(K_, col); it; ++it) {
      const int r = index[static_cast<size_t>(it.row())], c = index[static_cast<size_t>(it.col())];
      if (r >= 0 && c >= 0 && r >= c) triplets.emplace_back(r, c, it.value());
    }
  const int nf = static_cast<int>(free_dof_.size());
  K_free_.resize(nf, nf);
  K_free_.setFromTriplets(triplets.begin(), triplets.end());
  mass_free_.resize(nf);
  for (int f = 0; f < nf; ++f) mass_free_[f] = mass_[free_dof_[static_cast<size_t>(f)] / 3];
  free_index_ = index;
  if (cannula && cannula->enabled) {
    cannula->validate();
    cannula_ = *cannula;
    // As stiff as the explicit FE needle's cannula at its own step.
    const double dt_fe = options_.courant * needle.stable_time_step_ms();
    for (int node : boundary_nodes(needle.mesh())) {
      cannula_nodes_.push_back(node);
      cannula_k_.push_back(cannula->penalty_scale * mass_[node] / (dt_fe * dt_fe));
    }
  }
  state_.cannula_normal_N = Eigen::VectorXd::Zero(n);

  state_.w = state_.wd = state_.wdd = state_.load = state_.cannula_load = Eigen::VectorXd::Zero(3 * n);
  state_.old_load = state_.old_cannula_load = state_.load;
  state_.x = needle.mesh().X;
  state_.v = Eigen::MatrixX3d::Zero(n, 3);
  update_state();
  start_accelerations();
}

ImplicitNeedle::~ImplicitNeedle() = default;

void ImplicitNeedle::update_state() {
  const Eigen::RowVector3d d = (supports_.profile.displacement_mm(state_.time_ms) * supports_.direction).transpose();
  const Eigen::RowVector3d s = (supports_.profile.velocity_mm_per_ms(state_.time_ms) * supports_.direction).transpose();
  const Eigen::MatrixX3d& X = needle_.mesh().X;
  for (Eigen::Index i = 0; i < X.rows(); ++i)
    for (int k = 0; k < 3; ++k) {
      state_.x(i, k) = X(i, k) + d[k] + state_.w[3 * i + k];
      state_.v(i, k) = s[k] + state_.wd[3 * i + k];
    }
}

void ImplicitNeedle::evaluate_loads(NeedleLoads& loads) {
  state_.external.clear();
  loads.needle_forces(state_.x, state_.v, state_.time_ms, state_.external);
  state_.load.setZero();
  for (const auto& [node, f] : state_.external) {
    NEEDLE_REQUIRE(node >= 0 && node < state_.x.rows(), "external needle force on a node that does not exist");
    state_.load.segment<3>(3 * node) += f;
  }
  // The cannula's friction, from the last step's normal forces, against each node's sliding.
  state_.cannula_load.setZero();
  if (cannula_) {
    for (size_t k = 0; k < cannula_nodes_.size(); ++k) {
      const int n = cannula_nodes_[k];
      const double fn = state_.cannula_normal_N[n];
      if (!(fn > 0) || cannula_->friction == 0) continue;
      const double r = std::hypot(state_.x(n, 1), state_.x(n, 2));
      if (r == 0) continue;
      const Eigen::Vector3d radial(0, state_.x(n, 1) / r, state_.x(n, 2) / r);
      const Eigen::Vector3d vel = state_.v.row(n).transpose();
      const Eigen::Vector3d vt = vel - vel.dot(radial) * radial;
      const double speed = vt.norm();
      if (speed > 0) state_.cannula_load.segment<3>(3 * n) -= std::min(cannula_->friction * fn, 0.5 * mass_[n] / step_ms_ * speed) * vt / speed;
    }
  }
  if (!state_.load.allFinite() || !state_.cannula_load.allFinite())
    throw SolverError(fmt::format("the needle's loads became non-finite at t = {:.6g} ms", state_.time_ms));
}

void ImplicitNeedle::apply_loads(NeedleLoads& loads) {
  evaluate_loads(loads);
  // The state at t = 0 is in equilibrium with these loads: they start the first step's trapezoid.
  state_.old_load = state_.load;
  state_.old_cannula_load = state_.cannula_load;
  start_accelerations();
}

void ImplicitNeedle::start_accelerations() {
  // M w'' = f - K w - M e d'' with the drive's acceleration over the first step.
  const double h = step_ms_;
  const double accel = (supports_.profile.velocity_mm_per_ms(state_.time_ms + h) - supports_.profile.velocity_mm_per_ms(state_.time_ms)) / h;
  const Eigen::VectorXd elastic = K_ * state_.w;
  for (size_t f = 0; f < free_dof_.size(); ++f) {
    const int d = free_dof_[f];
    state_.wdd[d] = (state_.load[d] + state_.cannula_load[d] - elastic[d]) / mass_[d / 3] - accel * supports_.direction[d % 3];
  }
}

Eigen::SparseMatrix<double> ImplicitNeedle::step_matrix(double dt) const {
  Eigen::SparseMatrix<double> A = K_free_;
  for (Eigen::Index f = 0; f < A.rows(); ++f) A.coeffRef(f, f) += 4.0 / (dt * dt) * mass_free_[f];
  return A;
}

ImplicitNeedle::Factor& ImplicitNeedle::factor_for(double dt) {
  // A step within rounding of a factored one (time sums of whole steps) keeps its factor: the matrix differs
  // by 1e-9 of its mass term at most.
  for (size_t k = 0; k < factors_.size(); ++k)
    if (std::abs(dt - factors_[k].first) <= 1e-9 * factors_[k].first) {
      std::rotate(factors_.begin(), factors_.begin() + static_cast<std::ptrdiff_t>(k), factors_.begin() + static_cast<std::ptrdiff_t>(k) + 1);
      return *factors_.front().second;
    }
  const auto start = std::chrono::steady_clock::now();
  const Eigen::SparseMatrix<double> A = step_matrix(dt);
  auto factor = std::make_unique<Factor>();
  factor->llt.compute(A.selfadjointView<Eigen::Lower>());
  if (factor->llt.info() != Eigen::Success) throw SolverError("the implicit needle's step matrix could not be factored");
  constexpr size_t kKept = 10;
  if (factors_.size() == kKept) factors_.pop_back();
  factors_.insert(factors_.begin(), {dt, std::move(factor)});
  ++factorizations_;
  factor_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return *factors_.front().second;
}

void ImplicitNeedle::advance_to(double end_time_ms, NeedleLoads& loads) {
  // Steps of h, then the remainder (a whole number of grid steps when the coupled step plans it).
  const double tolerance = 1e-9 * step_ms_;
  while (end_time_ms - state_.time_ms > tolerance) step(end_time_ms - state_.time_ms > step_ms_ + tolerance ? step_ms_ : end_time_ms - state_.time_ms, loads);
}

bool ImplicitNeedle::speculate_advance(double end_time_ms, NeedleLoads& loads) {
  speculation_.reset();
  State before = state_;
  bool made = true;
  try {
    advance_to(end_time_ms, loads);
  } catch (...) {  // the real span will fail the same way, and say why
    made = false;
  }
  if (made) {
    speculation_ = std::move(state_);
    speculation_from_steps_ = before.steps;
    speculation_from_ms_ = before.time_ms;
    speculation_end_ms_ = end_time_ms;
  }
  state_ = std::move(before);
  return made;
}

bool ImplicitNeedle::adopt_speculation(double end_time_ms) {
  if (!speculation_) return false;
  const bool same = speculation_from_steps_ == state_.steps && speculation_from_ms_ == state_.time_ms && speculation_end_ms_ == end_time_ms;
  if (same) state_ = std::move(*speculation_);
  speculation_.reset();
  return same;
}

void ImplicitNeedle::step(double dt, NeedleLoads& loads) {
  Factor& factor = factor_for(dt);
  const double t0 = state_.time_ms, t1 = state_.time_ms + dt;
  const Eigen::Vector3d e = supports_.direction;
  double accel = (supports_.profile.velocity_mm_per_ms(t1) - supports_.profile.velocity_mm_per_ms(t0)) / dt;  // the drive's mean
  const double drive_step = supports_.profile.displacement_mm(t1) - supports_.profile.displacement_mm(t0);
  const Eigen::Vector3d momentum_before = momentum(), reaction_before = state_.drive_reaction;
  // A stop without deceleration within the step (moving at the travel's end, still after it) is a jump of the base's
  // velocity, not an acceleration the frame could carry as a load over the step: the held base stops at once and the
  // free nodes keep their velocity (the steel rings axially), so their velocity relative to the base grows by the
  // speed the base had, and the frame no longer accelerates.
  const double travel_end = supports_.profile.travel_end_time_ms();
  const bool stops_now = supports_.profile.decel_time_ms == 0 && t0 <= travel_end && travel_end < t1;
  if (stops_now) {
    const double jump = supports_.profile.velocity_mm_per_ms(t0) - supports_.profile.velocity_mm_per_ms(t1);
    for (const int d : free_dof_) state_.wd[d] += jump * e[d % 3];
    accel = 0;
  }
  // The loads at the step's start, held over it (the contact's and the cannula's).
  evaluate_loads(loads);

  const Eigen::Index nf = static_cast<Eigen::Index>(free_dof_.size());
  Eigen::VectorXd rhs(nf);
  const double c0 = 4.0 / (dt * dt), c1 = 4.0 / dt;
  for (Eigen::Index f = 0; f < nf; ++f) {
    const int d = free_dof_[static_cast<size_t>(f)];
    const double m = mass_free_[f];
    rhs[f] = state_.load[d] + state_.cannula_load[d] - m * accel * e[d % 3] + m * (c0 * state_.w[d] + c1 * state_.wd[d] + state_.wdd[d]);
  }
  Eigen::VectorXd w_free = factor.llt.solve(rhs);
  const double spring_energy_term = cannula_ ? hold_in_cannula(factor, w_free, supports_.profile.displacement_mm(t1) * e) : 0.0;
  if (!w_free.allFinite()) throw SolverError(fmt::format("the implicit needle's state became non-finite at t = {:.6g} ms", t1));
  Eigen::VectorXd dw = Eigen::VectorXd::Zero(state_.w.size());
  for (Eigen::Index f = 0; f < nf; ++f) {
    const int d = free_dof_[static_cast<size_t>(f)];
    const double wdd_new = c0 * (w_free[f] - state_.w[d] - dt * state_.wd[d]) - state_.wdd[d];
    state_.wd[d] += 0.5 * dt * (state_.wdd[d] + wdd_new);
    state_.wdd[d] = wdd_new;
    dw[d] = w_free[f] - state_.w[d];
    state_.w[d] = w_free[f];
  }
  state_.time_ms = t1;
  update_state();

  // Work of the held loads over the step (trapezoid of the loads at the step's two ends, as Newmark's
  // equilibrium at each end used them), through the absolute displacement.
  double external_work = 0, cannula_work = 0;
  for (Eigen::Index i = 0; i < state_.x.rows(); ++i) {
    const Eigen::Vector3d dx = dw.segment<3>(3 * i) + drive_step * e;
    external_work += 0.5 * (state_.old_load.segment<3>(3 * i) + state_.load.segment<3>(3 * i)).dot(dx);
    cannula_work += 0.5 * (state_.old_cannula_load.segment<3>(3 * i) + state_.cannula_load.segment<3>(3 * i)).dot(dx);
  }
  // The supports' reaction from the needle's momentum balance (elastic forces sum to zero).
  Eigen::Vector3d loads_sum = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < state_.x.rows(); ++i)
    loads_sum += 0.5 * (state_.old_load.segment<3>(3 * i) + state_.load.segment<3>(3 * i) + state_.old_cannula_load.segment<3>(3 * i) + state_.cannula_load.segment<3>(3 * i));
  state_.drive_reaction = (momentum() - momentum_before) / dt - loads_sum;
  state_.drive_impulse += dt * state_.drive_reaction;
  // The reaction's work through the base's motion. At a stop, the impulse J that stops the held base's mass works
  // J . (v_before + v_after) / 2 (the base's kinetic energy); until the stop the base moved under the reaction it had
  // before (after it, it does not move, and the reaction the stop sets up does no work).
  if (stops_now) {
    double held_mass = 0;
    for (const int i : supports_.driven) held_mass += mass_[i];
    const double v0 = supports_.profile.velocity_mm_per_ms(t0), v1 = supports_.profile.velocity_mm_per_ms(t1);
    const Eigen::Vector3d stop_impulse = held_mass * (v1 - v0) * e;
    state_.energy.drive_work_mJ += reaction_before.dot(drive_step * e) + stop_impulse.dot(0.5 * (v0 + v1) * e);
  } else {
    state_.energy.drive_work_mJ += state_.drive_reaction.dot(drive_step * e);
  }
  state_.energy.external_work_mJ += external_work;
  state_.energy.cannula_work_mJ += cannula_work;
  state_.old_load = state_.load;
  state_.old_cannula_load = state_.cannula_load;
  state_.energy.kinetic_mJ = 0.5 * mass_.dot(state_.v.rowwise().squaredNorm());
  // 1/2 w.K w from the equation just solved, (K + c0 M + U U^T) w = rhs + g on the free components (w = 0 on the
  // held ones): K w = rhs - c0 M w + (g - U U^T w), without a product with K. The springs' part is
  // hold_in_cannula's.
  double work = spring_energy_term;
  for (Eigen::Index f = 0; f < nf; ++f) work += w_free[f] * (rhs[f] - c0 * mass_free_[f] * w_free[f]);
  state_.energy.strain_mJ = 0.5 * work;
  ++state_.steps;
  if (!std::isfinite(state_.energy.kinetic_mJ) || !std::isfinite(state_.energy.strain_mJ))
    throw SolverError(fmt::format("the needle's energy became non-finite at t = {:.6g} ms", state_.time_ms));
  const double work_scale = std::max({std::abs(state_.energy.drive_work_mJ), std::abs(state_.energy.cannula_work_mJ), std::abs(state_.energy.external_work_mJ)});
  if (work_scale > 1e-6 && state_.energy.balance_error() > options_.max_energy_error)
    throw SolverError(fmt::format("the needle's energy balance drifted by {:.3g} % at t = {:.6g} ms (limit {:.3g} %)",
                                  100 * state_.energy.balance_error(), state_.time_ms, 100 * options_.max_energy_error));
}

const Eigen::VectorXd& ImplicitNeedle::column(Factor& factor, int dof) {
  auto it = factor.columns.find(dof);
  if (it != factor.columns.end()) return it->second;
  Eigen::VectorXd unit = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(free_dof_.size()));
  unit[free_index_[static_cast<size_t>(dof)]] = 1.0;
  return factor.columns.emplace(dof, factor.llt.solve(unit)).first->second;
}

double ImplicitNeedle::hold_in_cannula(Factor& factor, Eigen::VectorXd& w, const Eigen::Vector3d& drive) {
  const double r_in = cannula_->inner_radius_mm(), back = cannula_->front_x_mm - cannula_->length_mm, front = cannula_->front_x_mm;
  const Eigen::MatrixX3d& X = needle_.mesh().X;
  const Eigen::VectorXd w_free = w;  // without the cannula
  // A node's position at t + dt for free components wf (held ones stay at X + d e).
  const auto position = [&](int n, const Eigen::VectorXd& wf) {
    Eigen::Vector3d p = X.row(n).transpose() + drive;
    for (int k = 0; k < 3; ++k) {
      const int f = free_index_[3 * static_cast<size_t>(n) + k];
      if (f >= 0) p[k] += wf[f];
    }
    return p;
  };
  struct Spring {
    int node;
    double k;
    Eigen::Vector3d normal;  // radial, outward, at the state it joined
    double offset;           // r - n.(X + d e): the spring's force is k (offset - n.w) n
  };
  const auto passes = [&](size_t k, const Eigen::VectorXd& wf) {
    const Eigen::Vector3d p = position(cannula_nodes_[k], wf);
    return p.x() >= back && p.x() <= front && std::hypot(p.y(), p.z()) > r_in;
  };
  const auto spring = [&](size_t k, const Eigen::VectorXd& wf) {
    const Eigen::Vector3d p = position(cannula_nodes_[k], wf);
    const double r = std::hypot(p.y(), p.z());
    const Eigen::Vector3d normal(0, p.y() / r, p.z() / r);
    return Spring{cannula_nodes_[k], cannula_k_[k], normal, r_in - normal.dot(X.row(cannula_nodes_[k]).transpose() + drive)};
  };
  std::vector<Spring> active;
  std::vector<std::uint8_t> tried(cannula_nodes_.size(), 0);
  for (size_t k = 0; k < cannula_nodes_.size(); ++k)
    if (passes(k, w_free)) {
      active.push_back(spring(k, w_free));
      tried[k] = 1;
    }
  Eigen::VectorXd solved = w_free;
  double energy_term = 0;  // (g - U U^T w).w for the set that gave `solved`
  for (int iteration = 0; iteration < 10 && !active.empty(); ++iteration) {
    // Z = A^-1 U, U's column a = sqrt(k_a) n_a on node a's free components; the springs' constant part
    // k (r - n.(X + d e)) n joins the right-hand side, as the sum of its A^-1 columns.
    const Eigen::Index na = static_cast<Eigen::Index>(active.size()), nf = w_free.size();
    Eigen::MatrixXd Z = Eigen::MatrixXd::Zero(nf, na);
    Eigen::VectorXd shifted = w_free;
    for (Eigen::Index a = 0; a < na; ++a) {
      const Spring& s = active[static_cast<size_t>(a)];
      for (int k = 1; k < 3; ++k) {
        const int dof = 3 * s.node + k;
        if (free_index_[static_cast<size_t>(dof)] < 0 || s.normal[k] == 0) continue;
        const Eigen::VectorXd& c = column(factor, dof);
        Z.col(a) += std::sqrt(s.k) * s.normal[k] * c;
        shifted += s.k * s.offset * s.normal[k] * c;
      }
    }
    const auto project = [&](const Eigen::VectorXd& v) {  // U^T v: sqrt(k_a) n_a . v on node a
      Eigen::VectorXd out(na);
      for (Eigen::Index a = 0; a < na; ++a) {
        const Spring& s = active[static_cast<size_t>(a)];
        double sum = 0;
        for (int k = 1; k < 3; ++k) {
          const int f = free_index_[3 * static_cast<size_t>(s.node) + k];
          if (f >= 0) sum += s.normal[k] * v[f];
        }
        out[a] = std::sqrt(s.k) * sum;
      }
      return out;
    };
    Eigen::MatrixXd S = Eigen::MatrixXd::Identity(na, na);
    for (Eigen::Index b = 0; b < na; ++b) S.col(b) += project(Z.col(b));
    solved = shifted - Z * S.ldlt().solve(project(shifted));
    // Each spring's k (offset - n.w) (n.w) on its node's free components.
    energy_term = 0;
    for (const Spring& s : active) {
      double along = 0;
      for (int k = 1; k < 3; ++k) {
        const int f = free_index_[3 * static_cast<size_t>(s.node) + k];
        if (f >= 0) along += s.normal[k] * solved[f];
      }
      energy_term += s.k * (s.offset - along) * along;
    }
    // The set holds when no spring pulls and no node not yet tried passes the bore.
    std::vector<Spring> next;
    for (const Spring& s : active)
      if (s.normal.dot(position(s.node, solved)) > r_in) next.push_back(s);
    bool joined = false;
    for (size_t k = 0; k < cannula_nodes_.size(); ++k)
      if (!tried[k] && passes(k, solved)) {
        next.push_back(spring(k, solved));
        tried[k] = 1;
        joined = true;
      }
    const bool same = !joined && next.size() == active.size();
    active.swap(next);
    if (same) break;
  }
  w = solved;
  // The springs' forces at t + dt, and the report.
  state_.cannula_normal_N.setZero();
  state_.contact = CannulaContact{};
  for (const Spring& s : active) {
    const double gap = s.normal.dot(position(s.node, w)) - r_in;
    if (!(gap > 0)) continue;
    const double fn = s.k * gap;
    state_.cannula_normal_N[s.node] = fn;
    state_.cannula_load.segment<3>(3 * s.node) -= fn * s.normal;
    ++state_.contact.nodes_in_contact;
    state_.contact.max_penetration_mm = std::max(state_.contact.max_penetration_mm, gap);
    state_.contact.normal_force_N += fn;
    state_.contact.force_N -= fn * s.normal;
  }
  state_.max_cannula_penetration_mm = std::max(state_.max_cannula_penetration_mm, state_.contact.max_penetration_mm);
  if (state_.contact.max_penetration_mm > options_.max_penetration_mm)
    throw SolverError(fmt::format("the needle passed the cannula's bore by {:.3g} mm at t = {:.6g} ms (limit {:.3g} mm): "
                                  "runaway penetration", state_.contact.max_penetration_mm, state_.time_ms, options_.max_penetration_mm));
  return energy_term;
}

void ImplicitNeedle::add_summary(nlohmann::json& summary) const {
  summary["needle_time_step_ms"] = step_ms_;
  summary["needle_factorizations"] = factorizations_;
  summary["needle_factor_s"] = factor_s_;
  summary["needle_free_dofs"] = free_dof_.size();
  summary["needle_max_cannula_penetration_mm"] = state_.max_cannula_penetration_mm;
}

}  // namespace needle
