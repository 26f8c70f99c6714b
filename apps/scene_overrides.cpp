#include "apps/scene_overrides.h"

#include <algorithm>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/input_error.h"
#include "runs/insertion_run.h"
#include "runs/model_levels.h"
#include "solver/contact/needle_tissue_contact.h"

namespace needle {

void apply_scene_overrides(Scene& scene, const SceneOverrides& o) {
  // NaN: not given; otherwise checked, with an InputError naming the flag.
  auto given = [](double v, const char* flag) {
    NEEDLE_REQUIRE(std::isnan(v) || (std::isfinite(v) && v > 0), fmt::format("{} must be a positive number (got {})", flag, v));
    return !std::isnan(v);
  };
  auto given_or_zero = [](double v, const char* flag) {
    NEEDLE_REQUIRE(std::isnan(v) || (std::isfinite(v) && v >= 0), fmt::format("{} must be a number >= 0 (got {})", flag, v));
    return !std::isnan(v);
  };
  if (!o.model.empty()) apply_model_level(scene, o.model);
  const bool travel_given = given(o.travel_mm, "--travel-mm"), speed_given = given(o.speed_m_per_s, "--speed-m-per-s");
  const bool decel_given = given_or_zero(o.decel_time_ms, "--decel-time-ms"), hold_given = given_or_zero(o.hold_ms, "--hold-ms");
  if (travel_given) scene.motion.travel_mm = o.travel_mm;
  if (speed_given) scene.motion.speed_mm_per_ms = o.speed_m_per_s;  // m/s = mm/ms
  if (decel_given) scene.motion.decel_time_ms = o.decel_time_ms;
  if (hold_given) scene.motion.hold_ms = o.hold_ms;
  if (travel_given || speed_given || decel_given || hold_given)
    scene.motion.validate(travel_given ? "--travel-mm" : speed_given ? "--speed-m-per-s" : decel_given ? "--decel-time-ms" : "--hold-ms");
  if (given(o.spacing_mm, "--spacing-mm")) scene.tissue.spacing_mm = o.spacing_mm;
  if (o.path_refinement) {
    NEEDLE_REQUIRE(*o.path_refinement >= 1 && *o.path_refinement <= 8,
                   fmt::format("--path-refinement must be an integer from 1 to 8 (got {})", *o.path_refinement));
    scene.tissue.path_refinement = *o.path_refinement;
  }
  if (given(o.mesh_size_mm, "--mesh-size-mm")) scene.needle.mesh.size_mm = o.mesh_size_mm;
  if (o.no_needle_cut) scene.tissue.separation.needle_cut = false;
  if (!std::isnan(o.tissue_nu)) {
    scene.tissue.material.nu = o.tissue_nu;
    scene.tissue.material.validate();
  }
  if (!o.tissue_law.empty()) {
    scene.tissue.material.law = tissue_law_from_name(o.tissue_law);
    scene.tissue.material.validate();
  }
  NEEDLE_REQUIRE(std::isnan(o.tissue_friction) || o.tissue_friction <= kMaxFrictionCoefficient,
                 fmt::format("--tissue-friction must lie in [0, {:g}] (a friction coefficient; the paper's 0.18; got {})", kMaxFrictionCoefficient,
                             o.tissue_friction));
  if (given_or_zero(o.tissue_friction, "--tissue-friction"))
    scene.tissue.friction = scene.tissue.contact.friction = o.tissue_friction;  // as the scene key tissue.friction sets both
  if (!o.tissue_size_mm.empty()) {
    const std::vector<double>& v = o.tissue_size_mm;
    NEEDLE_REQUIRE(v.size() == 3 && std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x) && x > 0; }),
                   fmt::format("--tissue-size-mm must be three positive lengths x,y,z (got {})", fmt::join(v, ",")));
    scene.tissue.size_mm = {v[0], v[1], v[2]};
  }
  if (given_or_zero(o.slit_half_height_mm, "--slit-half-height-mm")) {
    NEEDLE_REQUIRE(o.slit_half_height_mm == 0 || scene.needle.half_model,
                   "--slit-half-height-mm needs a half model: the slit opens the symmetry plane");
    scene.tissue.separation.slit.half_height_mm = o.slit_half_height_mm;
  }
  if (!std::isnan(o.relaxing_shear_fraction) || !std::isnan(o.relaxation_time_ms)) {
    NEEDLE_REQUIRE(std::isnan(o.relaxation_time_ms) || !std::isnan(o.relaxing_shear_fraction) || scene.tissue.material.viscoelastic(),
                   "--relaxation-time-ms needs --relaxing-shear-fraction (the share of the shear stress that relaxes)");
    if (!std::isnan(o.relaxing_shear_fraction)) scene.tissue.material.relaxing_shear_fraction = o.relaxing_shear_fraction;
    if (!std::isnan(o.relaxation_time_ms)) scene.tissue.material.relaxation_time_ms = o.relaxation_time_ms;
    scene.tissue.material.validate();
  }
  if (given_or_zero(o.cutting_pressure_MPa, "--cutting-pressure-mpa")) scene.tissue.cutting.pressure_MPa = o.cutting_pressure_MPa;
  if (given_or_zero(o.crack_reach_mm, "--crack-reach-mm")) scene.tissue.separation.crack.reach_mm = o.crack_reach_mm;
  if (!o.crack_angles_deg.empty()) {
    NEEDLE_REQUIRE(std::all_of(o.crack_angles_deg.begin(), o.crack_angles_deg.end(), [](double a) { return std::isfinite(a) && a >= -180 && a <= 180; }),
                   fmt::format("--crack-angles-deg must be angles from -180 to 180 degrees (got {})", fmt::join(o.crack_angles_deg, ",")));
    scene.tissue.separation.crack.angles_deg = o.crack_angles_deg;
  }
  if (given_or_zero(o.crack_lead_mm, "--crack-lead-mm")) scene.tissue.separation.crack.lead_mm = o.crack_lead_mm;
  // The crack's shape without a crack would be dropped from scene.json without a word.
  NEEDLE_REQUIRE((o.crack_angles_deg.empty() && std::isnan(o.crack_lead_mm)) || scene.tissue.separation.crack.enabled(),
                 "--crack-angles-deg and --crack-lead-mm shape the tip's crack: they need --crack-reach-mm above 0 (or a scene with "
                 "tissue.contact.crack_reach_mm)");
  if (given(o.groove_start_mm, "--groove-start-mm")) {
    NEEDLE_REQUIRE(scene.needle.mesh_file.empty() && !scene.needle.plain_rod,
                   "--groove-start-mm moves the groove of a ground tip: it needs a preset, d_a or a recipe (not a plain rod or a mesh file)");
    scene.needle.groove_start_mm = o.groove_start_mm;
  }
  if (given_or_zero(o.contact_skin_mm, "--contact-skin-mm")) scene.tissue.contact.skin_mm = o.contact_skin_mm;
  if (given(o.contact_stiffness_factor, "--contact-stiffness-factor")) {
    NEEDLE_REQUIRE(o.contact_stiffness_factor <= 1e4, fmt::format("--contact-stiffness-factor must be at most 1e4 (got {})", o.contact_stiffness_factor));
    scene.tissue.contact.stiffness_factor = o.contact_stiffness_factor;
  }
  if (given_or_zero(o.tissue_entry_x_mm, "--tissue-entry-x-mm")) {
    NEEDLE_REQUIRE(o.tissue_entry_x_mm < scene.motion.travel_mm,
                   fmt::format("--tissue-entry-x-mm must be less than the travel ({} mm), or the tip never reaches the tissue (got {})",
                               scene.motion.travel_mm, o.tissue_entry_x_mm));
    scene.tissue.entry_x_mm = o.tissue_entry_x_mm;
  }
  scene = apply_scene_settings(scene, o.settings);
}

void add_scene_override_options(CLI::App* c, SceneOverrides& o) {
  std::string levels;
  for (const ModelLevel& level : model_levels()) levels += fmt::format("{}{}: {}", levels.empty() ? "" : "; ", level.name, level.description);
  c->add_option("--model", o.model, fmt::format("The model level ({}; default: the scene's; the run defaults' fast)", levels));
  c->add_option("--set", o.settings,
                "Set any scene key, KEY=VALUE with the scene file's dotted names and units, e.g. --set tissue.material.nu=0.49 "
                "--set 'motion.travel=10 mm' (docs/scenes.md); repeatable, applied after the other flags");
  c->add_option("--travel-mm", o.travel_mm, "Insertion travel (default 30)");
  c->add_option("--spacing-mm", o.spacing_mm, "Tissue particle spacing (default 0.4)");
  c->add_option("--path-refinement", o.path_refinement,
                "Particles this many times finer within 1.2 mm of the needle's path (default: the scene's)");
  c->add_flag("--no-needle-cut", o.no_needle_cut,
              "The needle does not cut the bonds its body crosses; the tissue separates by bond failure alone, as in the paper's "
              "model (scene key tissue.contact.cuts_bonds)");
  c->add_option("--tissue-nu", o.tissue_nu, "Tissue Poisson ratio (the paper's 0.45; scene key tissue.material.nu)");
  c->add_option("--tissue-friction", o.tissue_friction, "Needle-tissue friction coefficient (the paper's 0.18; scene key tissue.friction)");
  c->add_option("--tissue-law", o.tissue_law,
                "Tissue constitutive law: mat018 (the paper's card, default) or stiffening_elastic (E at small strain plus the "
                "measured k eps^n; scene key tissue.material.law)");
  c->add_option("--speed-m-per-s", o.speed_m_per_s,
                "Insertion speed after the 0.75 ms ramp (the paper's model 8 m/s; its experiment fired at about 4 m/s; "
                "scene key motion.speed_m_per_s)");
  c->add_option("--decel-time-ms", o.decel_time_ms,
                "Decelerate the base to rest over this time, ending at the travel (default 0: the paper's model ends at full speed; "
                "scene key motion.decel_time_ms)");
  c->add_option("--hold-ms", o.hold_ms,
                "Hold the needle's base still this long after the travel, so that delta is read at rest as the experiment reads it "
                "(default 0: at the end of the travel, as the paper's model; without --decel-time-ms the stop is instantaneous "
                "and the needle rings; scene key motion.hold_ms)");
  c->add_option("--tissue-size-mm", o.tissue_size_mm,
                "The tissue block's length x, height y (centred on the path) and half width z, e.g. 40,16,6 (the paper's "
                "40,8,2; the experiment's phantom: 100 long, 30 high, 80 wide; the faces y = +-Y/2 and z = Z are fixed; scene key tissue.size_mm)")
      ->expected(3)
      ->delimiter(',');
  c->add_option("--slit-half-height-mm", o.slit_half_height_mm,
                "The tissue also opens in the symmetry plane behind the tip point, within this distance of the rod's axis, so the "
                "needle can push it aside instead of only up and down (0.5: as tall as the rod; default 0: no slit; scene key "
                "tissue.contact.slit_half_height_mm; half models only)");
  c->add_option("--relaxing-shear-fraction", o.relaxing_shear_fraction,
                "Viscoelastic gel: this share g of the shear stress relaxes, s(t) = s0 (1 - g (1 - exp(-t/tau))) under a held strain; "
                "E stays the instantaneous modulus (default 0: the paper's card, no relaxation; scene key "
                "tissue.material.relaxing_shear_fraction)");
  c->add_option("--relaxation-time-ms", o.relaxation_time_ms,
                "The relaxation's time constant tau (default 1 ms; scene key tissue.material.relaxation_time_ms)");
  c->add_option("--cutting-pressure-mpa", o.cutting_pressure_MPa,
                "Cutting resistance: a pressure on the tip facets that advance into the tissue, the work of separating it "
                "(default 0: cutting costs nothing, as in the paper's model; scene key tissue.contact.cutting_pressure_MPa)");
  c->add_option("--crack-reach-mm", o.crack_reach_mm,
                "The tip drives a crack past the rod's outline: the bonds across planar fins that leave tip point A are cut as the "
                "tip passes, up to this distance from A (the rod's radius is 0.5; default 0: the tissue separates along the "
                "needle's surface only; scene key tissue.contact.crack_reach_mm)");
  c->add_option("--crack-angles-deg", o.crack_angles_deg,
                "The crack's fins, as directions in the cross-section from A: 0 toward +z (a horizontal crack at A's height), "
                "90 up, -90 down, e.g. 0 or 48,-55 (default 0; scene key tissue.contact.crack_angles_deg)")
      ->delimiter(',');
  c->add_option("--crack-lead-mm", o.crack_lead_mm,
                "The crack's front runs this far ahead of tip point A, so the gel splits before the tip reaches it (default 0: "
                "it opens as the tip passes; scene key tissue.contact.crack_lead_mm)");
  c->add_option("--groove-start-mm", o.groove_start_mm,
                "The groove's front wall this far behind tip point A. The paper does not give it; the presets' 3 mm clears the SB "
                "bevel's heel (2.3 mm) (default: the recipe's; scene key needle.groove_start_mm)");
  c->add_option("--contact-skin-mm", o.contact_skin_mm,
                fmt::format("The penalty contact's skin: particles feel the needle this far outside its surface, so the needle acts that much "
                            "thicker (a numerical parameter, 0 is exact contact; default {:g}; scene key tissue.contact.skin_mm)", ContactOptions{}.skin_mm));
  c->add_option("--contact-stiffness-factor", o.contact_stiffness_factor,
                fmt::format("The penalty's stiffness as a multiple of the particle's own (a numerical parameter: stiffer holds particles nearer "
                            "the skin and takes more tissue steps; default {:g}; scene key tissue.contact.stiffness_factor)",
                            ContactOptions{}.stiffness_factor));
  c->add_option("--tissue-entry-x-mm", o.tissue_entry_x_mm,
                "The block's entry face this far ahead of tip point A's start (default 0: at the cannula's front). The particle "
                "lattice starts at the entry face, so a fraction of the spacing (e.g. 0.1 at 0.2 mm particles) shifts the lattice "
                "against the needle's path: the run-to-run scatter of a result is measured so (the tip then ends that much less "
                "deep in the tissue; scene key tissue.entry_x_mm)");
}

std::string scene_override_arguments(const SceneOverrides& o) {
  std::string line;
  auto number = [&](const char* flag, double v) {  // NaN: not given
    if (!std::isnan(v)) line += fmt::format(" {} {}", flag, v);
  };
  auto list = [&](const char* flag, const std::vector<double>& v) {
    if (!v.empty()) line += fmt::format(" {} {}", flag, fmt::join(v, ","));
  };
  if (!o.model.empty()) line += fmt::format(" --model {}", o.model);
  for (const std::string& setting : o.settings) line += fmt::format(" --set '{}'", setting);
  number("--travel-mm", o.travel_mm);
  number("--spacing-mm", o.spacing_mm);
  number("--mesh-size-mm", o.mesh_size_mm);
  if (o.path_refinement) line += fmt::format(" --path-refinement {}", *o.path_refinement);
  if (o.no_needle_cut) line += " --no-needle-cut";
  number("--tissue-nu", o.tissue_nu);
  number("--tissue-friction", o.tissue_friction);
  if (!o.tissue_law.empty()) line += fmt::format(" --tissue-law {}", o.tissue_law);
  number("--speed-m-per-s", o.speed_m_per_s);
  number("--decel-time-ms", o.decel_time_ms);
  number("--hold-ms", o.hold_ms);
  list("--tissue-size-mm", o.tissue_size_mm);
  number("--slit-half-height-mm", o.slit_half_height_mm);
  number("--relaxing-shear-fraction", o.relaxing_shear_fraction);
  number("--relaxation-time-ms", o.relaxation_time_ms);
  number("--cutting-pressure-mpa", o.cutting_pressure_MPa);
  number("--crack-reach-mm", o.crack_reach_mm);
  list("--crack-angles-deg", o.crack_angles_deg);
  number("--crack-lead-mm", o.crack_lead_mm);
  number("--groove-start-mm", o.groove_start_mm);
  number("--contact-skin-mm", o.contact_skin_mm);
  number("--contact-stiffness-factor", o.contact_stiffness_factor);
  number("--tissue-entry-x-mm", o.tissue_entry_x_mm);
  return line;
}

std::string default_calibration_after(const Scene& scene, const SceneOverrides& overrides) {
  Scene probe = scene;
  apply_scene_overrides(probe, overrides);
  return default_calibration_file(model_level_of(probe));
}

}  // namespace needle
