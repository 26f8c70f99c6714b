#include "runs/insertion_output.h"

#include <cmath>
#include <fmt/format.h>

#include "mesher/vtk_files.h"
#include "runs/scene_needle.h"
#include "solver/insertion/strain_probes.h"

namespace needle {
namespace {

// Broken bonds per particle.
Eigen::VectorXd broken_bonds(const SpgTissue& tissue) {
  Eigen::VectorXd count = Eigen::VectorXd::Zero(tissue.particles().size());
  for (const Bond& b : tissue.bonds().bonds)
    if (b.broken) {
      count[b.i] += 1;
      count[b.j] += 1;
    }
  return count;
}

}  // namespace

InsertionOutput::InsertionOutput(const RunFolder& folder, const ContactSurface& surface,
                                 const std::vector<std::unique_ptr<SeparationModel>>& separations)
    : folder_(folder), surface_(surface) {
  history_.open(folder.path("history.csv"));
  history_ << "time_ms,insertion_mm,tip_dx_mm,tip_dy_mm,tip_dz_mm,deflection_mm,drive_force_x_N,drive_force_y_N,drive_force_z_N,"
              "contact_force_x_N,contact_force_y_N,contact_force_z_N,particles_in_contact,particles_inside,max_depth_mm,"
              "bonds_broken,tissue_kinetic_mJ,tissue_internal_mJ,needle_kinetic_mJ,needle_strain_mJ,drive_work_mJ,"
              "cannula_work_mJ,contact_work_mJ,penalty_energy_mJ,friction_dissipation_mJ,relinearisation_energy_mJ,energy_balance_error,"
              "coupling_step_ms,needle_steps,groove_fill,groove_floor_contact_fraction";
  for (const auto& separation : separations)
    for (const std::string& column : separation->history_columns()) history_ << "," << column;
  history_ << "\n";
  facets_.open(folder.path("facet_forces.csv"));
  facets_ << "time_ms,insertion_mm";
  for (const std::string& tag : surface.tag_names())
    if (tag != "symmetry")
      facets_ << fmt::format(",{0}_particles,{0}_normal_N,{0}_friction_N,{0}_fx_N,{0}_fy_N,{0}_fz_N", tag);
  facets_ << "\n";
}

void InsertionOutput::record(const CoupledInsertion& run, int tip, const GrooveFill& groove) {
  const NeedleModel& n = run.needle();
  const Eigen::RowVector3d u = n.positions_mm().row(tip) - n.mesh().X.row(tip);
  const Eigen::Vector3d drive = n.drive_displacement_mm(), reaction = n.drive_reaction_N();
  const ContactReport& c = run.contact();
  const InsertionEnergy& e = run.energy();
  history_ << fmt::format(
      "{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{},{},{:.6g},{},{:.9g},{:.9g},{:.9g},{:.9g},"
      "{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.6g},{:.6g},{},{:.4f},{:.4f}",
      run.time_ms(), drive.norm(), u.x(), u.y(), u.z(), u.y() - drive.y(), reaction.x(), reaction.y(), reaction.z(),
      c.force_on_needle_N.x(), c.force_on_needle_N.y(), c.force_on_needle_N.z(), c.particles_in_contact, c.particles_inside,
      c.max_depth_mm, run.bonds_broken(), e.tissue_kinetic_mJ, e.tissue_internal_mJ, e.needle_kinetic_mJ, e.needle_strain_mJ,
      e.drive_work_mJ, e.cannula_work_mJ, e.contact_work_mJ, e.penalty_energy_mJ, e.friction_dissipation_mJ, e.relinearisation_energy_mJ, e.balance_error(),
      run.last_step_ms(), run.needle_steps(), groove.groove_fill, groove.floor_contact_fraction);
  for (const auto& separation : run.separations())
    for (const std::string& value : separation->history_values()) history_ << "," << value;
  history_ << "\n";
  facets_ << fmt::format("{:.9g},{:.9g}", run.time_ms(), drive.norm());
  for (size_t k = 0; k < surface_.tag_names().size(); ++k) {
    if (surface_.tag_names()[k] == "symmetry") continue;
    const FacetContact& f = c.facets[k];
    facets_ << fmt::format(",{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}", f.particles, f.normal_N, f.friction_N, f.force_N.x(), f.force_N.y(),
                           f.force_N.z());
  }
  facets_ << "\n";
  history_.flush();  // a run killed from outside still leaves its history
  facets_.flush();
}

void InsertionOutput::frame(const CoupledInsertion& run) {
  const int index = static_cast<int>(needle_frames_.size());
  const std::string needle_name = fmt::format("frames/needle_{:04}.vtu", index);
  write_needle_vtu(folder_.path(needle_name).string(), run.needle());
  needle_frames_.emplace_back(run.time_ms(), needle_name);

  const TissueParticles& p = run.tissue().particles();
  const Eigen::Index np = p.size();
  Eigen::MatrixX3d x(np, 3), u(np, 3), v(np, 3);
  Eigen::VectorXd plastic(np), effective(np), min_principal(np), mises(np), contact(np);
  const std::vector<std::uint8_t> in_contact = run.contact_model().in_contact();
  for (Eigen::Index i = 0; i < np; ++i) {
    const size_t s = static_cast<size_t>(i);
    x.row(i) = p.position_mm[s].transpose();
    u.row(i) = (p.position_mm[s] - p.initial_mm[s]).transpose();
    v.row(i) = p.velocity_mm_per_ms[s].transpose();
    plastic[i] = p.plastic_strain[s];
    effective[i] = p.effective_strain[s];
    min_principal[i] = min_principal_log_strain(p.elastic_left_cauchy_green[s]);
    const Mat3d dev = p.stress_MPa[s] - p.stress_MPa[s].trace() / 3 * Mat3d::Identity();
    mises[i] = std::sqrt(1.5 * dev.squaredNorm());
    contact[i] = in_contact[s];
  }
  std::vector<VtkField> fields = {{"displacement_mm", u},
                                  {"velocity_m_per_s", v},
                                  {"plastic_strain", plastic},
                                  {"effective_strain", effective},
                                  {"min_principal_strain", min_principal},
                                  {"von_mises_MPa", mises},
                                  {"broken_bonds", broken_bonds(run.tissue())},
                                  {"in_contact", contact}};
  // A fired cannula's frames mark the particles in its bore behind its front (the sample, and the clearance's layer).
  if (const CannulaFiring* firing = run.cannula_firing()) {
    const std::vector<std::uint8_t> inside = firing->inside_bore(p.position_mm, run.needle().positions_mm(), run.time_ms());
    Eigen::VectorXd in_cannula(np);
    for (Eigen::Index i = 0; i < np; ++i) in_cannula[i] = inside[static_cast<size_t>(i)];
    fields.push_back({"in_cannula", in_cannula});
  }
  const std::string tissue_name = fmt::format("frames/tissue_{:04}.vtp", index);
  write_vtp(folder_.path(tissue_name).string(), x, fields, VtkEncoding::binary);
  tissue_frames_.emplace_back(run.time_ms(), tissue_name);
}

void InsertionOutput::finish() {
  history_.close();
  facets_.close();
  write_pvd(folder_.path("needle.pvd"), needle_frames_);
  write_pvd(folder_.path("tissue.pvd"), tissue_frames_);
}

}  // namespace needle
