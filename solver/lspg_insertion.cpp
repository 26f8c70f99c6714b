#include "solver/lspg_insertion.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fmt/format.h>

#include "geometry/input_error.h"
#include "solver/solver_error.h"

namespace needle {

void CouplingOptions::validate(const std::string& where) const {
  NEEDLE_REQUIRE(std::isfinite(max_step_ms) && max_step_ms >= 0, fmt::format("{}: max_step_ms must be zero or positive", where));
  NEEDLE_REQUIRE(std::isfinite(contact_courant) && contact_courant > 0 && contact_courant <= 1,
                 fmt::format("{}: contact_courant must lie in (0, 1]", where));
  NEEDLE_REQUIRE(std::isfinite(max_energy_error) && max_energy_error > 0, fmt::format("{}: max_energy_error must be positive", where));
  NEEDLE_REQUIRE(std::isfinite(max_depth_mm) && max_depth_mm > 0, fmt::format("{}: max_depth_mm must be positive", where));
}

double InsertionEnergy::balance_error() const {
  const double inputs = drive_work_mJ + cannula_work_mJ + tissue_reaction_work_mJ + body_work_mJ;
  const double stored = (tissue_kinetic_mJ - tissue_initial_kinetic_mJ) + (needle_kinetic_mJ + needle_strain_mJ - needle_initial_mJ) +
                        tissue_internal_mJ + (penalty_energy_mJ - initial_penalty_energy_mJ) + friction_dissipation_mJ;
  // The largest energy the run has held or exchanged, the energy present at t = 0 included.
  const double scale = std::max({std::abs(drive_work_mJ), std::abs(cannula_work_mJ), std::abs(tissue_reaction_work_mJ), std::abs(body_work_mJ),
                                 std::abs(tissue_kinetic_mJ), std::abs(needle_kinetic_mJ), std::abs(needle_strain_mJ),
                                 std::abs(tissue_internal_mJ), std::abs(penalty_energy_mJ), std::abs(friction_dissipation_mJ),
                                 std::abs(initial_energy_mJ()), 1e-300});
  return std::abs(inputs - stored) / scale;
}

double InsertionEnergy::initial_energy_mJ() const { return tissue_initial_kinetic_mJ + needle_initial_mJ + initial_penalty_energy_mJ; }

double InsertionEnergy::external_work_mJ() const {
  return std::max({std::abs(drive_work_mJ), std::abs(cannula_work_mJ), std::abs(tissue_reaction_work_mJ), std::abs(body_work_mJ)});
}

LspgInsertion::LspgInsertion(NeedleDynamics& needle, SpgTissue& tissue, const ContactSurface& surface, const ContactOptions& contact,
                             const CouplingOptions& coupling)
    : needle_(needle),
      tissue_(tissue),
      options_(coupling),
      tissue_dynamics_(tissue, {}, coupling.tissue_body_acceleration_mm_per_ms2),
      contact_(surface, tissue.particles(), tissue.material(), contact),
      bond_cut_(surface),
      slit_(needle.needle().mesh().X, contact.slit),
      crack_(needle.needle().mesh().X, contact.crack) {
  options_.validate();
  NEEDLE_REQUIRE(needle.steps() == 0 && needle.time_ms() == 0, "the coupled run must start with a needle at t = 0");
  NEEDLE_REQUIRE(surface.reference_positions().rows() == needle.positions_mm().rows(),
                 "the contact surface belongs to another needle mesh");
  contact_.set_needle(needle.needle().nodal_mass_g(), needle.time_step_ms());
  // The contact at t = 0 (particles placed within the skin already push), on both bodies.
  contact_.begin_step(tissue.particles(), needle.positions_mm(), needle.velocities_mm_per_ms(), 0.0,
                      tissue_dynamics_.time_step_ms(options_.contact_courant * contact_.stable_time_step_ms()));
  // The needle subcycles inside the tissue's step, after the particles' drift, at the contact evaluation
  // (see the header); the particles then get the contact at the step's end.
  needle_.set_external_forces([this](const Eigen::MatrixX3d& x, const Eigen::MatrixX3d& v, double t, NeedleDynamics::NodalForces& f) {
    contact_.needle_forces(x, v, t, f);
  });
  tissue_dynamics_.set_external_forces([this](std::vector<Vec3d>& force) {
    if (!in_step_) return contact_.last_particle_forces(force);  // the state at t = 0
    contact_.begin_step(tissue_.particles(), needle_.positions_mm(), needle_.velocities_mm_per_ms(), step_start_ms_, step_dt_ms_);
    needle_.advance_to(step_start_ms_ + step_dt_ms_);
    contact_.end_step(force);
  });
  energy_.needle_initial_mJ = needle_.energy().initial_mJ;
  energy_.initial_penalty_energy_mJ = contact_.report().penalty_energy_mJ;
  energy_.tissue_initial_kinetic_mJ = tissue_dynamics_.energy().initial_kinetic_mJ;
  update_energy();
}

Eigen::Vector3d LspgInsertion::tissue_momentum() const {
  const TissueParticles& p = tissue_.particles();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::int64_t i = 0; i < p.size(); ++i) sum += p.mass_g[static_cast<size_t>(i)] * p.velocity_mm_per_ms[static_cast<size_t>(i)];
  return sum;
}

void LspgInsertion::update_energy() {
  const NeedleEnergy& n = needle_.energy();
  const EnergyBalance& t = tissue_dynamics_.energy();
  energy_.tissue_kinetic_mJ = t.kinetic_mJ;
  energy_.tissue_internal_mJ = -t.model_work_mJ;
  energy_.tissue_reaction_work_mJ = t.constraint_work_mJ;
  energy_.body_work_mJ = t.body_work_mJ;
  energy_.needle_kinetic_mJ = n.kinetic_mJ;
  energy_.needle_strain_mJ = n.strain_mJ;
  energy_.drive_work_mJ = n.drive_work_mJ;
  energy_.cannula_work_mJ = n.cannula_work_mJ;
  energy_.contact_work_mJ = n.external_work_mJ + t.external_work_mJ;
  energy_.penalty_energy_mJ = contact_.report().penalty_energy_mJ;
  energy_.friction_dissipation_mJ = contact_.friction_dissipation_mJ();
  energy_.relinearisation_energy_mJ = contact_.relinearisation_energy_mJ();
}

void LspgInsertion::step(double end_time_ms) {
  const double t = time_ms();
  double cap = end_time_ms - t;
  NEEDLE_REQUIRE(cap > 0, "the insertion has reached its end time");
  if (options_.max_step_ms > 0) cap = std::min(cap, options_.max_step_ms);
  cap = std::min(cap, options_.contact_courant * contact_.stable_time_step_ms());
  if (!options_.subcycling) cap = std::min(cap, needle_.time_step_ms());
  double dt = tissue_dynamics_.time_step_ms(cap);
  // A whole number of needle steps per coupling step, so that the needle never takes a sliver of a step.
  const double needle_dt = needle_.time_step_ms();
  if (std::isfinite(needle_dt) && dt > needle_dt && dt < end_time_ms - t) dt = std::floor(dt / needle_dt) * needle_dt;
  step_start_ms_ = t;
  step_dt_ms_ = dt;
  in_step_ = true;
  try {
    tissue_dynamics_.step(dt);  // the needle subcycles inside, at the contact evaluation
  } catch (...) {
    in_step_ = false;
    throw;
  }
  in_step_ = false;
  if (contact_.options().cuts_bonds) {
    const auto start = std::chrono::steady_clock::now();
    tissue_.cut_bonds(bond_cut_.bonds_through_needle(tissue_.bonds(), tissue_.particles().position_mm, needle_.positions_mm()));
    bond_cut_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  slit_.open(tissue_.particles(), needle_.positions_mm());
  if (crack_.options().enabled()) {
    const auto start = std::chrono::steady_clock::now();
    bonds_cut_by_crack_ += tissue_.cut_bonds(crack_.bonds_across(tissue_.bonds(), tissue_.particles().position_mm, needle_.positions_mm()));
    crack_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  ++steps_;
  last_dt_ms_ = dt;
  update_energy();

  max_inside_ = std::max(max_inside_, contact_.report().particles_inside);
  max_depth_ = std::max(max_depth_, contact_.report().max_depth_mm);
  if (contact_.report().max_depth_mm > options_.max_depth_mm)
    throw SolverError(fmt::format("runaway penetration: a tissue particle is {:.3g} mm inside the needle at t = {:.6g} ms (limit {:.3g} mm)",
                                  contact_.report().max_depth_mm, time_ms(), options_.max_depth_mm));
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

}  // namespace needle
