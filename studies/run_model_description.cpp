#include "studies/run_model_description.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <vector>

#include "studies/paper_results.h"
#include "runs/scene.h"
#include "geometry/grinding_recipe.h"
#include "solver/needle/insertion_profile.h"
#include "runs/model_levels.h"
#include "solver/contact/contact_laws.h"
#include "solver/contact/needle_tissue_contact.h"
#include "solver/needle/needle_models.h"
#include "solver/tissue/tissue_material.h"

namespace needle {
using json = nlohmann::json;

std::string describe_run_model(const json& scene, long particles) {
  std::string d;
  if (scene.contains("tissue") && scene["tissue"].is_object()) {
    const json& t = scene["tissue"];
    const double h = t.value("spacing_mm", kNaN);
    const int refinement = t.value("path_refinement", 1);
    d = refinement > 1
            ? fmt::format("{:g} mm particles, {:g} mm within {:g} mm of the path", h, h / refinement, t.value("path_half_width_mm", kNaN))
            : fmt::format("{:g} mm particles", h);
    const bool needle_cuts = t.contains("contact") && t["contact"].value("cuts_bonds", false);
    d += fmt::format(" ({} particles); the needle {} the bonds its body passes through", particles, needle_cuts ? "cuts" : "does not cut");
    // The paper's card is the default and goes unnamed; another law is said.
    if (t.contains("material") &&
        tissue_law_from_name(t["material"].value("law", tissue_law_name(TissueLaw::mat018))) == TissueLaw::stiffening_elastic)
      d += "; the tissue stiffens as measured (stiffening_elastic: 3 G eps + k eps^n)";
    // The card has no relaxation and goes unnamed; a viscoelastic gel is said.
    const json material = t.value("material", json::object());
    const double relaxing_share = material.value("relaxing_shear_fraction", 0.0);
    if (relaxing_share > 0)
      d += fmt::format("; the gel relaxes viscoelastically ({:g} of the shear stress, time constant {:g} ms)", relaxing_share,
                       material.value("relaxation_time_ms", TissueMaterial{}.relaxation_time_ms));
    // The paper's 40 x 8 x 2 mm half block goes unnamed; another block is said.
    const TissueScene paper_block;
    if (t.contains("size_mm") && t["size_mm"].is_array() && t["size_mm"].size() == 3) {
      const Eigen::Vector3d size{t["size_mm"][0].get<double>(), t["size_mm"][1].get<double>(), t["size_mm"][2].get<double>()};
      if (size != paper_block.size_mm)
        d += fmt::format("; a {:g} x {:g} x {:g} mm half block (the paper's: {:g} x {:g} x {:g})", size.x(), size.y(), size.z(),
                         paper_block.size_mm.x(), paper_block.size_mm.y(), paper_block.size_mm.z());
    }
    // No slit is the default and goes unnamed; a slit is said.
    const json contact = t.value("contact", json::object());
    const double slit_mm = contact.value("slit_half_height_mm", 0.0);
    if (slit_mm > 0)
      d += fmt::format("; the tissue also splits in the symmetry plane behind the tip, {:g} mm either side of the rod's axis", slit_mm);
    // No crack past the rod is the default and goes unnamed; a crack is said.
    const double crack_mm = contact.value("crack_reach_mm", 0.0);
    if (crack_mm > 0) {
      std::vector<double> angles = contact.value("crack_angles_deg", std::vector<double>{0.0});
      d += fmt::format(
          "; the tip drives a crack past the rod: fins from the tip point at {} deg in the cross-section "
          "(0: horizontal), {:g} mm long",
          fmt::join(angles, ", "), crack_mm);
      const double lead_mm = contact.value("crack_lead_mm", 0.0);
      if (lead_mm > 0) d += fmt::format(", running {:g} mm ahead of the tip", lead_mm);
    }
    // The default lip goes unnamed: crushed 0.45 mm deep since 2026-11-28 (a depth fitted on HMB, which the paper report
    // names in a section of its own). Any other lip is said: a scene of 2026-11-27 or 28 with no depth crushed the whole
    // lip; a scene from before 2026-11-27 has no mode (the lip stayed as the tissue is).
    const std::string lip_mode = contact.value("lip_release_mode", std::string("off"));
    const double lip_below_mm = contact.value("lip_release_below_mm", 0.0);
    const json lip_depth = contact.value("lip_release_depth_mm", json(kWholeLipText));
    const bool whole_lip = lip_depth.is_string();
    const std::string released = lip_mode == "free" ? "is cut loose (lip release free)" : "is crushed (lip release)";
    if (lip_mode == "off")
      d += "; the lip below the tip point stays as the tissue is (no lip release)";
    else if (lip_mode == "crushed" && lip_below_mm == 0 && !whole_lip && lip_depth.get<double>() == kSceneCrushedLipDepthMm)
      ;  // the default
    else if (lip_below_mm == 0 && whole_lip)
      d += "; the whole lip below the tip point " + released;
    else {
      d += fmt::format("; the tissue the tip meets from {:g} mm below its tip point", lip_below_mm);
      d += whole_lip ? std::string(" down to the rod's bottom") : fmt::format(" to {:g} mm", lip_below_mm + lip_depth.get<double>());
      d += ", inside the rod's outline, " + released;
    }
    // The default contact (ContactOptions: skin 0.02 mm, stiffness factor 30) goes unnamed; another is said.
    const ContactOptions default_contact;
    const double skin_mm = contact.value("skin_mm", default_contact.skin_mm);
    const double stiffness_factor = contact.value("stiffness_factor", default_contact.stiffness_factor);
    if (skin_mm != default_contact.skin_mm || stiffness_factor != default_contact.stiffness_factor)
      d += fmt::format("; the contact's skin is {:g} mm and its stiffness factor {:g} (the defaults: {:g} and {:g})", skin_mm,
                       stiffness_factor, default_contact.skin_mm, default_contact.stiffness_factor);
    // The full model level's needle and contact (the FE needle, the penalty; a scene writes them only when not those) go
    // unnamed, and a needle that does not take the coupling step with that contact (the rigid one, said elsewhere);
    // another needle model or contact law is said in its registry's words, with the model level it makes.
    const ModelLevel& full = *find_model_level(kReferenceModelLevel);
    const std::string law = contact.value("law", full.contact_law);
    const std::string needle_model = scene.contains("needle") && scene["needle"].is_object()
                                         ? scene["needle"].value("model", full.needle_model)
                                         : full.needle_model;
    const ContactLawEntry& law_entry = contact_law(law);
    const NeedleModelEntry& needle_entry = ::needle::needle_model(needle_model);
    const json solver = scene.value("solver", json::object());
    const bool mass_scaled = solver.value("tissue_mass_scaling", false) || solver.value("tissue_mass_scaling_dt_ms", 0.0) > 0;
    // Spherical kernel supports (the full model's) go unnamed; ellipsoids are said.
    const bool ellipsoids = t.contains("spg") && t["spg"].is_object() && t["spg"].value("support", std::string("sphere")) == "ellipsoid";
    // Multi-rate stepping of the tissue (solver.tissue_rate_levels; one rate goes unnamed).
    const int rate_levels = solver.value("tissue_rate_levels", 0);
    const std::string multirate =
        rate_levels > 0 ? fmt::format(", the tissue away from the needle stepped at up to {} coupling steps (multi-rate)", 1 << rate_levels) : "";
    std::string level_flag;  // the level these keys make, if any but the full one
    for (const ModelLevel& level : model_levels())
      if (level.name != full.name && level.needle_model == needle_model && level.contact_law == law &&
          level.tissue_mass_scaling == mass_scaled && (level.support == SupportShape::ellipsoid) == ellipsoids &&
          level.tissue_rate_levels == rate_levels)
        level_flag = fmt::format(" (--model {})", level.name);
    if (law != full.contact_law || needle_entry.takes_coupling_step)
      d += fmt::format("; {} and {}{}{}{}{}", needle_entry.phrase, law_entry.phrase, mass_scaled ? ", the tissue selectively mass-scaled" : "",
                       ellipsoids ? ", ellipsoidal kernel supports" : "", multirate, level_flag);
    else if (mass_scaled || ellipsoids || !multirate.empty())
      d += fmt::format("; {}{}", mass_scaled && ellipsoids ? "the tissue selectively mass-scaled, ellipsoidal kernel supports"
                                 : mass_scaled    ? "the tissue selectively mass-scaled"
                                 : ellipsoids     ? "ellipsoidal kernel supports"
                                                  : "",
                       mass_scaled || ellipsoids ? multirate : multirate.substr(multirate.empty() ? 0 : 2));
    // No cutting resistance is the default and goes unnamed; a resistance is said.
    const double cutting_MPa = contact.value("cutting_pressure_MPa", 0.0);
    if (cutting_MPa > 0)
      d += fmt::format("; cutting the tissue costs work: a pressure of {:g} MPa on the tip facets that advance into it", cutting_MPa);
    // The block's entry face at the tip's start is the default and goes unnamed; a shifted one is said.
    const double entry_x_mm = t.value("entry_x_mm", 0.0);
    if (entry_x_mm != 0)
      d += fmt::format(
          "; the block's entry face is {:g} mm ahead of the tip's start (the particle lattice shifted "
          "against the path; the tip ends that much less deep)",
          entry_x_mm);
  }
  // The paper's drive (8 m/s, read at full speed) goes unnamed; another speed, a stop or a hold is said.
  const InsertionProfile paper_drive;
  const json motion = scene.value("motion", json::object());
  const double speed_m_per_s = motion.value("speed_m_per_s", paper_drive.speed_mm_per_ms);
  const double decel_ms = motion.value("decel_time_ms", paper_drive.decel_time_ms);
  const double hold_ms = motion.value("hold_ms", paper_drive.hold_ms);
  if (speed_m_per_s != paper_drive.speed_mm_per_ms)
    d += fmt::format("; the needle is driven at {:g} m/s (the paper's model: {:g})", speed_m_per_s, paper_drive.speed_mm_per_ms);
  if (decel_ms != paper_drive.decel_time_ms) d += fmt::format("; the base decelerates to rest over {:g} ms", decel_ms);
  if (hold_ms != paper_drive.hold_ms) d += fmt::format("; delta is read after the base is held still for {:g} ms", hold_ms);
  // The presets' groove (its front wall 3 mm behind A) goes unnamed; another start is said.
  const json needle_scene = scene.value("needle", json::object());
  if (needle_scene.contains("groove_start_mm"))
    d += fmt::format("; the groove starts {:g} mm behind the tip point (the presets': {:g})", needle_scene["groove_start_mm"].get<double>(),
                     Groove{}.start_behind_tip_mm);
  return d;
}

}  // namespace needle
