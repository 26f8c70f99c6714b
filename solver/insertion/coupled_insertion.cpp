#include "solver/insertion/coupled_insertion.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "core/input_error.h"
#include "core/parallel.h"
#include "core/solver_error.h"
#include "solver/contact/contact_laws.h"

namespace needle {

void CouplingOptions::validate(const std::string& where) const {
  NEEDLE_REQUIRE(std::isfinite(max_step_ms) && max_step_ms >= 0, fmt::format("{}: max_step_ms must be zero or positive", where));
  NEEDLE_REQUIRE(std::isfinite(contact_courant) && contact_courant > 0 && contact_courant <= 1,
                 fmt::format("{}: contact_courant must lie in (0, 1]", where));
  NEEDLE_REQUIRE(std::isfinite(max_energy_error) && max_energy_error > 0, fmt::format("{}: max_energy_error must be positive", where));
  NEEDLE_REQUIRE(std::isfinite(max_depth_mm) && max_depth_mm > 0, fmt::format("{}: max_depth_mm must be positive", where));
  NEEDLE_REQUIRE(std::isfinite(tissue_mass_scaling_dt_ms) && tissue_mass_scaling_dt_ms >= 0,
                 fmt::format("{}: tissue_mass_scaling_dt_ms must be zero or positive", where));
  NEEDLE_REQUIRE(std::isfinite(tissue_ahead_margin_mm) && tissue_ahead_margin_mm >= 0,
                 fmt::format("{}: tissue_ahead_margin_mm must be zero or positive", where));
  NEEDLE_REQUIRE(tissue_rate_levels >= 0 && tissue_rate_levels <= 10, fmt::format("{}: tissue_rate_levels must lie in [0, 10]", where));
  NEEDLE_REQUIRE(std::isfinite(tissue_rate_needle_margin_mm), fmt::format("{}: tissue_rate_needle_margin_mm must be finite", where));
  NEEDLE_REQUIRE(std::isfinite(tissue_rate_safety) && tissue_rate_safety >= 1, fmt::format("{}: tissue_rate_safety must be at least 1", where));
}

CoupledInsertion::CoupledInsertion(NeedleModel& needle, SpgTissue& tissue, const ContactSurface& surface, const ContactOptions& contact,
                                   std::vector<std::unique_ptr<SeparationModel>> separations, const CouplingOptions& coupling,
                                   const CuttingOptions& cutting)
    : needle_(needle),
      tissue_(tissue),
      options_(coupling),
      tissue_dynamics_(tissue, {}, coupling.tissue_body_acceleration_mm_per_ms2),
      contact_(make_tissue_contact(surface, tissue.particles(), tissue.material(), contact)),
      cutting_(cutting.enabled() ? std::make_unique<CuttingResistance>(surface, tissue.particles(), cutting) : nullptr),
      separations_(std::move(separations)) {
  loads_.contact = contact_.get();
  loads_.cutting = cutting_.get();
  options_.validate();
  NEEDLE_REQUIRE(needle.steps() == 0 && needle.time_ms() == 0, "the coupled run must start with a needle at t = 0");
  NEEDLE_REQUIRE(surface.reference_positions().rows() == needle.positions_mm().rows(), "the contact surface belongs to another needle mesh");
  contact_->set_needle(needle.nodal_mass_g(), needle.time_step_ms());
  tissue_dynamics_.set_mass_scaling(options_.tissue_mass_scaling_dt_ms);
  tissue_dynamics_.set_rate_levels(options_.tissue_rate_levels, options_.tissue_rate_safety);
  // The contact at t = 0 (particles placed within a penalty's skin already push), on both bodies.
  contact_->begin_step(tissue.particles(), needle.positions_mm(), needle.velocities_mm_per_ms(), 0.0,
                       tissue_dynamics_.time_step_ms(contact_->max_time_step_ms(options_.contact_courant)));
  needle_.apply_loads(loads_);
  contact_->last_particle_forces(contact_force_N_);
  tissue_dynamics_.set_external_forces(contact_force_N_);
  energy_.start(needle_.energy(), tissue_dynamics_.energy(), *contact_, cutting_.get());
}

void CoupledInsertion::step(double end_time_ms) {
  const double t = time_ms();
  if (tissue_dynamics_.at_rate_cycle_start() && options_.tissue_rate_needle_margin_mm >= 0) hold_particles_near_needle_fast();
  StepLimit limit = StepLimit::tissue;
  const double dt = tissue_dynamics_.kick_and_drift(plan_time_step(end_time_ms, limit));
  ++step_limits_[static_cast<size_t>(limit)];
  contact_->begin_step(tissue_.particles(), needle_.positions_mm(), needle_.velocities_mm_per_ms(), t, dt);
  // The needle's span, or the one taken ahead beside the last step's forces when it was this one (needle_ahead):
  // adopted where advance_to would run, after everything that reads the needle at the step's start.
  if (options_.tissue_beside_needle) {
    mark_particles_away_from_needle();
    needle_x_before_ = needle_.positions_mm();
    if (adopt_needle_span(t + dt)) tissue_.update_points_ahead(dt, still_);
    else run_beside([&] { needle_.advance_to(t + dt, loads_); }, [&] { tissue_.update_points_ahead(dt, still_); });
    needle_motion_mm_ = (needle_.positions_mm() - needle_x_before_).rowwise().norm().maxCoeff();
  } else if (!adopt_needle_span(t + dt)) {
    needle_.advance_to(t + dt, loads_);
  }
  contact_->end_step(tissue_dynamics_, needle_.positions_mm(), needle_.velocities_mm_per_ms(), contact_force_N_);
  if (firing_) firing_->push_tissue(tissue_dynamics_, needle_.positions_mm(), t + dt, dt);
  if (take_next_needle_span_ahead(t + dt, dt)) {
    // The next span on the guess that the next step is as long as this one; its loads are set now (end_step) and the
    // tissue's update does not touch them. begin_step is called again before the next span.
    run_beside(
        [&] {
          contact_->begin_step(tissue_.particles(), needle_.positions_mm(), needle_.velocities_mm_per_ms(), t + dt, dt);
          needle_.speculate_advance(t + dt + dt, loads_);
        },
        [&] { tissue_dynamics_.finish_step(&contact_force_N_); });
  } else {
    tissue_dynamics_.finish_step(&contact_force_N_);
  }
  for (const std::unique_ptr<SeparationModel>& separation : separations_) separation->apply(tissue_, needle_);
  ++steps_;
  last_dt_ms_ = dt;
  energy_.update(needle_.energy(), tissue_dynamics_.energy(), *contact_, cutting_.get(), firing_ ? firing_->work_mJ() : 0.0);
  check_health();
}

bool CoupledInsertion::take_next_needle_span_ahead(double next_start_ms, double dt_ms) const {
  if (!options_.needle_ahead || cutting_ || !contact_->needle_loads_set_at_step_end() || !needle_.can_speculate()) return false;
  // The cannula's stroke holds the needle (held_needle.h refuses spans that reach its hold) and pushes the tissue.
  if (firing_ && next_start_ms + dt_ms >= firing_->stroke().start_time_ms) return false;
  return true;
}

bool CoupledInsertion::adopt_needle_span(double end_time_ms) {
  const bool adopted = needle_.adopt_speculation(end_time_ms);
  if (adopted) ++needle_spans_ahead_;
  return adopted;
}

void CoupledInsertion::fire_cannula(CannulaFiring* firing) {
  NEEDLE_REQUIRE(steps_ == 0, "the cannula's firing is set before the first step");
  firing_ = firing;
}

void CoupledInsertion::StepLoads::needle_forces(const Eigen::MatrixX3d& x, const Eigen::MatrixX3d& v, double t, NodalForces& f) {
  contact->needle_forces(x, v, t, f);
  if (cutting) cutting->needle_forces(x, v, t, f);
}

ContactReport CoupledInsertion::contact() const {
  ContactReport report = contact_->report();
  if (cutting_) cutting_->add_to(report);
  return report;
}

void CoupledInsertion::flag_particles_by_needle_box(double margin_mm, bool inside, std::vector<std::uint8_t>& flags) const {
  Eigen::Vector3d lo, hi;
  contact_->surface().closed_bounds(needle_.positions_mm(), lo, hi);
  lo.array() -= margin_mm;
  hi.array() += margin_mm;
  const std::vector<Vec3d>& p = tissue_.particles().position_mm;
  flags.resize(p.size());
  parallel_for(static_cast<std::int64_t>(p.size()), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) {
      const Vec3d& q = p[static_cast<size_t>(i)];
      const bool outside = (q.array() < lo.array()).any() || (q.array() > hi.array()).any();
      flags[static_cast<size_t>(i)] = outside != inside;
    }
  });
}

// A fired cannula moves particles beyond the needle's surface, up to its outer radius: once it may move within the coming
// cycle of the rate levels, the margins around the needle's box must reach that far (before, the particles are the same
// as without it). The particles away from the needle then have their supports past the cannula too (the same results,
// a matter of speed); the particles held at the coupling step reach past it already unless the scene narrowed their
// margin (the paper scene's 0.2 mm and the cannula's 0.135 mm).
double CoupledInsertion::cannula_reach_mm() const {
  if (!firing_) return 0.0;
  const double cycle_ms = 2.0 * (1 << options_.tissue_rate_levels) * std::max(last_dt_ms_, tissue_dynamics_.time_step_ms());
  return time_ms() + cycle_ms >= firing_->stroke().start_time_ms ? firing_->reach_beyond_rod_mm() + kCannulaReachSafetyMm : 0.0;
}

void CoupledInsertion::mark_particles_away_from_needle() {
  const double margin = contact_->options().skin_mm + 2 * needle_motion_mm_ + options_.tissue_ahead_margin_mm;
  flag_particles_by_needle_box(std::max(margin, contact_->options().skin_mm + cannula_reach_mm()), false, still_);
}

void CoupledInsertion::hold_particles_near_needle_fast() {
  std::vector<std::uint8_t> fast;
  flag_particles_by_needle_box(contact_->options().skin_mm + std::max(options_.tissue_rate_needle_margin_mm, cannula_reach_mm()), true, fast);
  tissue_dynamics_.set_fast_particles(std::move(fast));
}

const char* step_limit_name(StepLimit limit) {
  switch (limit) {
    case StepLimit::interval_end: return "interval_end";
    case StepLimit::max_step: return "max_step";
    case StepLimit::contact: return "contact";
    case StepLimit::needle_step: return "needle_step";
    case StepLimit::tissue: return "tissue";
  }
  return "unknown";
}

double CoupledInsertion::plan_time_step(double end_time_ms, StepLimit& limit) const {
  const double t = time_ms();
  double cap = end_time_ms - t;
  NEEDLE_REQUIRE(cap > 0, "the insertion has reached its end time");
  limit = StepLimit::interval_end;
  const auto lower = [&cap, &limit](double bound, StepLimit why) {
    if (bound < cap) {
      cap = bound;
      limit = why;
    }
  };
  if (options_.max_step_ms > 0) lower(options_.max_step_ms, StepLimit::max_step);
  lower(contact_->max_time_step_ms(options_.contact_courant), StepLimit::contact);
  const double needle_dt = needle_.time_step_ms(), grid = needle_.step_grid_ms();
  if (!options_.subcycling) lower(needle_dt, StepLimit::needle_step);
  double dt = tissue_dynamics_.time_step_ms(cap);
  if (dt < cap) limit = StepLimit::tissue;
  // A whole number of the needle's grid per coupling step, so that the needle never takes a sliver of a step
  // (below one grid step: its half, quarter ...).
  if (std::isfinite(grid) && dt < end_time_ms - t) {
    if (dt > grid) dt = std::floor(dt / grid) * grid;
    else if (dt < grid) dt = grid / std::exp2(std::ceil(std::log2(grid / dt)));
  }
  return dt;
}

void CoupledInsertion::check_health() {
  max_inside_ = std::max(max_inside_, contact_->report().particles_inside);
  max_depth_ = std::max(max_depth_, contact_->report().max_depth_mm);
  if (contact_->report().max_depth_mm > options_.max_depth_mm)
    throw SolverError(fmt::format("runaway penetration: a tissue particle is {:.3g} mm inside the needle at t = {:.6g} ms (limit {:.3g} mm)",
                                  contact_->report().max_depth_mm, time_ms(), options_.max_depth_mm));
  // The balance is checked once the work done from outside exceeds a nanojoule and the energy the run
  // started with (particles inside the contact's skin at t = 0 release theirs in the first steps, when
  // the drive has done almost nothing: measured against that, the release is not a drift).
  if (energy_.external_work_mJ() > std::max(1e-6, std::abs(energy_.initial_energy_mJ()))) {
    const double error = energy_.balance_error();
    max_energy_error_ = std::max(max_energy_error_, error);
    if (error > options_.max_energy_error)
      throw SolverError(fmt::format("the insertion's energy balance drifted by {:.3g} % at t = {:.6g} ms (limit {:.3g} %)", 100 * error,
                                    time_ms(), 100 * options_.max_energy_error));
  }
}

Eigen::Vector3d CoupledInsertion::tissue_momentum() const {
  const TissueParticles& p = tissue_.particles();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::int64_t i = 0; i < p.size(); ++i) sum += p.mass_g[static_cast<size_t>(i)] * p.velocity_mm_per_ms[static_cast<size_t>(i)];
  return sum;
}

}  // namespace needle
