#include "runs/insertion_measures.h"

#include <algorithm>
#include <cmath>

namespace needle {
using nlohmann::json;

namespace {

// The particles pulled back into the needle's reference frame (as the contact does), and the tissue block's x range there.
struct PulledBackTissue {
  std::vector<Eigen::Vector3d> points;
  double min_x_mm = 0, max_x_mm = 0;
};

PulledBackTissue pulled_back_tissue(CoupledInsertion& run, const Scene& scene) {
  const double drive_x = run.needle().drive_displacement_mm().x();
  return {run.contact_model().pull_back(run.tissue().particles().position_mm, run.needle().positions_mm()),
          scene.tissue.entry_x_mm - drive_x, scene.tissue.entry_x_mm + scene.tissue.size_mm.x() - drive_x};
}

// Per particle: in contact with a triangle of the needle's groove floor.
std::vector<std::uint8_t> touching_groove_floor(NeedleTissueContact& contact, size_t particles) {
  std::vector<std::uint8_t> touches(particles, 0);
  const ContactSurface& surface = contact.surface();
  for (const auto& [particle, triangle] : contact.contacts())
    if (triangle >= 0 && surface.tag_names()[static_cast<size_t>(surface.triangle_tag(triangle))] == "groove_floor")
      touches[static_cast<size_t>(particle)] = 1;
  return touches;
}

}  // namespace

GrooveFill run_groove_fill(CoupledInsertion& run, const SceneNeedle& needle, const Scene& scene) {
  if (!needle.groove) return {};
  const TissueParticles& p = run.tissue().particles();
  NeedleTissueContact& contact = run.contact_model();
  PulledBackTissue tissue = pulled_back_tissue(run, scene);
  GrooveFillInput in;
  in.groove = *needle.groove;
  in.radius_mm = needle.radius_mm;
  in.tissue_min_x_mm = tissue.min_x_mm;
  in.tissue_max_x_mm = tissue.max_x_mm;
  in.reference_points = std::move(tissue.points);
  in.spacing_mm = p.spacing_mm;
  in.touches_floor = touching_groove_floor(contact, in.reference_points.size());
  return measure_groove_fill(in);
}

std::vector<std::uint8_t> groove_floor_contacts(CoupledInsertion& run) {
  return touching_groove_floor(run.contact_model(), run.tissue().particles().position_mm.size());
}

TissueSample run_tissue_sample(CoupledInsertion& run, const SceneNeedle& needle, const CannulaFiring& firing,
                               std::vector<std::uint8_t> touched_floor) {
  const TissueParticles& p = run.tissue().particles();
  TissueSampleInput in;
  in.reference_points = firing.reference_points(p.position_mm, run.needle().positions_mm());
  in.spacing_mm = p.spacing_mm;
  in.volume_mm3 = p.reference_volume_mm3;
  const double density = run.tissue().material().density_g_per_mm3();
  in.mass_g.resize(in.volume_mm3.size());
  for (size_t i = 0; i < in.mass_g.size(); ++i) in.mass_g[i] = density * in.volume_mm3[i];  // physical, whatever the mass scaling
  in.touches_floor = std::move(touched_floor);
  in.bore_radius_mm = firing.tube().mid_radius_mm();
  const double front = firing.stroke().front_x_mm(run.time_ms());
  in.x_lo_mm = firing.stroke().start_x_mm;
  in.x_hi_mm = front;
  if (needle.groove) {
    in.x_lo_mm = std::max(in.x_lo_mm, needle.groove->back_x_mm);
    in.x_hi_mm = std::min(in.x_hi_mm, needle.groove->front_x_mm);
    in.floor_y_mm = needle.groove->floor_y_mm;
    in.contact_skin_mm = run.contact_model().options().skin_mm;
  }
  return measure_tissue_sample(in);
}

StrainProbes run_strain_probes(CoupledInsertion& run, const SceneNeedle& needle, const Scene& scene) {
  const TissueParticles& p = run.tissue().particles();
  NeedleTissueContact& contact = run.contact_model();
  PulledBackTissue tissue = pulled_back_tissue(run, scene);
  StrainProbeInput in;
  in.reference_points = std::move(tissue.points);
  in.tissue_min_x_mm = tissue.min_x_mm;
  in.tissue_max_x_mm = tissue.max_x_mm;
  in.spacing_mm = p.spacing_mm;
  in.min_principal_strain.resize(p.elastic_left_cauchy_green.size());
  for (size_t i = 0; i < in.min_principal_strain.size(); ++i) in.min_principal_strain[i] = min_principal_log_strain(p.elastic_left_cauchy_green[i]);
  const ContactSurface& surface = contact.surface();
  in.contact_tag.assign(in.reference_points.size(), -1);
  for (const auto& [particle, triangle] : contact.contacts())
    if (triangle >= 0) in.contact_tag[static_cast<size_t>(particle)] = surface.triangle_tag(triangle);
  in.tag_names = surface.tag_names();
  in.tip_point = needle.tip_point;
  in.groove = needle.groove;
  in.radius_mm = needle.radius_mm;
  return probe_strains(in);
}

json strain_probes_json(const StrainProbes& probes, double insertion_mm, double deflection_mm) {
  auto region = [](const StrainRegion& r) {
    auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    return json{{"particles", r.particles}, {"median", number(r.median)}, {"p05", number(r.p05)}, {"min", number(r.min)}};
  };
  return {{"insertion_mm", insertion_mm},
          {"deflection_mm", deflection_mm},
          {"tip_top", region(probes.tip_top)},
          {"below_tip", region(probes.below_tip)},
          {"groove", region(probes.groove)}};
}

}  // namespace needle
