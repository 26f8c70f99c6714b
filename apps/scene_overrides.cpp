#include "apps/scene_overrides.h"

#include <fmt/format.h>

#include "core/input_error.h"
#include "runs/model_levels.h"
#include "solver/contact/needle_tissue_contact.h"

namespace needle {

const std::vector<SceneFlagRow>& scene_flag_rows() {
  using T = SceneFlagRow::Takes;
  static const std::vector<SceneFlagRow> rows = {
      {"--travel-mm", "motion.travel_mm", T::value, "", "Insertion travel (default 30; scene key motion.travel_mm)"},
      {"--spacing-mm", "tissue.spacing_mm", T::value, "", "Tissue particle spacing (default 0.4; scene key tissue.spacing_mm)"},
      {"--mesh-size-mm", "needle.mesh.size_mm", T::value, "", "Needle mesh size over the tip and groove (run default 0.4; scene key needle.mesh.size_mm)"},
      {"--path-refinement", "tissue.path_refinement", T::value, "",
       "Particles this many times finer within 1.2 mm of the needle's path (default: the scene's; scene key tissue.path_refinement)"},
      {"--no-needle-cut", "tissue.separation.needle_cut", T::nothing, "false",
       "The needle does not cut the bonds its body crosses; the tissue separates by bond failure alone, as in the paper's "
       "model (scene key tissue.separation.needle_cut)"},
      {"--tissue-nu", "tissue.material.nu", T::value, "", "Tissue Poisson ratio (the paper's 0.45; scene key tissue.material.nu)"},
      {"--tissue-friction", "tissue.friction", T::value, "", "Needle-tissue friction coefficient (the paper's 0.18; scene key tissue.friction)"},
      {"--tissue-law", "tissue.material.law", T::value, "",
       "Tissue constitutive law: mat018 (the paper's card, default) or stiffening_elastic (E at small strain plus the "
       "measured k eps^n; scene key tissue.material.law)"},
      {"--speed-m-per-s", "motion.speed_m_per_s", T::value, "",
       "Insertion speed after the 0.75 ms ramp (the paper's model 8 m/s; its experiment fired at about 4 m/s; "
       "scene key motion.speed_m_per_s)"},
      {"--decel-time-ms", "motion.decel_time_ms", T::value, "",
       "Decelerate the base to rest over this time, ending at the travel (default 0: the paper's model ends at full speed; "
       "scene key motion.decel_time_ms)"},
      {"--hold-ms", "motion.hold_ms", T::value, "",
       "Hold the needle's base still this long after the travel, so that delta is read at rest as the experiment reads it "
       "(default 0: at the end of the travel, as the paper's model; without --decel-time-ms the stop is instantaneous "
       "and the needle rings; scene key motion.hold_ms)"},
      {"--tissue-size-mm", "tissue.size_mm", T::list, "",
       "The tissue block's length x, height y (centred on the path) and half width z, e.g. 40,16,6 (the paper's "
       "40,8,2; the experiment's phantom: 100 long, 30 high, 80 wide; the faces y = +-Y/2 and z = Z are fixed; scene key tissue.size_mm)",
       3},
      {"--slit-half-height-mm", "tissue.separation.slit.half_height_mm", T::value, "",
       "The tissue also opens in the symmetry plane behind the tip point, within this distance of the rod's axis, so the "
       "needle can push it aside instead of only up and down (0.5: as tall as the rod; default 0: no slit; scene key "
       "tissue.separation.slit.half_height_mm; half models only)"},
      {"--relaxing-shear-fraction", "tissue.material.relaxing_shear_fraction", T::value, "",
       "Viscoelastic gel: this share g of the shear stress relaxes, s(t) = s0 (1 - g (1 - exp(-t/tau))) under a held strain; "
       "E stays the instantaneous modulus (default 0: the paper's card, no relaxation; scene key "
       "tissue.material.relaxing_shear_fraction)"},
      {"--relaxation-time-ms", "tissue.material.relaxation_time_ms", T::value, "",
       "The relaxation's time constant tau (default 1 ms; scene key tissue.material.relaxation_time_ms)"},
      {"--cutting-pressure-mpa", "tissue.cutting.pressure_MPa", T::value, "",
       "Cutting resistance: a pressure on the tip facets that advance into the tissue, the work of separating it "
       "(default 0: cutting costs nothing, as in the paper's model; scene key tissue.cutting.pressure_MPa)"},
      {"--crack-reach-mm", "tissue.separation.crack.reach_mm", T::value, "",
       "The tip drives a crack past the rod's outline: the bonds across planar fins that leave tip point A are cut as the "
       "tip passes, up to this distance from A (the rod's radius is 0.5; default 0: the tissue separates along the "
       "needle's surface only; scene key tissue.separation.crack.reach_mm)"},
      {"--crack-angles-deg", "tissue.separation.crack.angles_deg", T::list, "",
       "The crack's fins, as directions in the cross-section from A: 0 toward +z (a horizontal crack at A's height), "
       "90 up, -90 down, e.g. 0 or 48,-55 (default 0; scene key tissue.separation.crack.angles_deg)"},
      {"--crack-lead-mm", "tissue.separation.crack.lead_mm", T::value, "",
       "The crack's front runs this far ahead of tip point A, so the gel splits before the tip reaches it (default 0: "
       "it opens as the tip passes; scene key tissue.separation.crack.lead_mm)"},
      {"--fire-cannula", "cannula.firing.enabled", T::nothing, "true",
       "After the travel, fire the cannula over the groove (the trucut's third step) and measure the tissue sample it "
       "encloses: its length I_s, volume and mass (summary.json \"sample\"; default off; scene section cannula.firing)"},
      {"--firing-speed-m-per-s", "cannula.firing.speed_m_per_s", T::value, "",
       "The fired cannula's speed (the paper's device: about 4 m/s, the default; scene key cannula.firing.speed_m_per_s)"},
      {"--firing-throw-mm", "cannula.firing.throw_mm", T::value, "",
       "The fired cannula's throw from its front at rest (default: to the groove's far end; the paper's device throws "
       "25 mm; scene key cannula.firing.throw_mm)"},
      {"--groove-start-mm", "needle.groove_start_mm", T::value, "",
       "The groove's front wall this far behind tip point A. The paper does not give it; the presets' 3 mm clears the SB "
       "bevel's heel (2.3 mm) (default: the recipe's; scene key needle.groove_start_mm)"},
      {"--contact-skin-mm", "tissue.contact.skin_mm", T::value, "",
       fmt::format("The penalty contact's skin: particles feel the needle this far outside its surface, so the needle acts that much "
                   "thicker (a numerical parameter, 0 is exact contact; default {:g}; scene key tissue.contact.skin_mm)", ContactOptions{}.skin_mm)},
      {"--contact-stiffness-factor", "tissue.contact.stiffness_factor", T::value, "",
       fmt::format("The penalty's stiffness as a multiple of the particle's own (a numerical parameter: stiffer holds particles nearer "
                   "the skin and takes more tissue steps; default {:g}; scene key tissue.contact.stiffness_factor)",
                   ContactOptions{}.stiffness_factor)},
      {"--tissue-entry-x-mm", "tissue.entry_x_mm", T::value, "",
       "The block's entry face this far ahead of tip point A's start (default 0: at the cannula's front). The particle "
       "lattice starts at the entry face, so a fraction of the spacing (e.g. 0.1 at 0.2 mm particles) shifts the lattice "
       "against the needle's path: the run-to-run scatter of a result is measured so (the tip then ends that much less "
       "deep in the tissue; scene key tissue.entry_x_mm)"},
  };
  return rows;
}

namespace {

const SceneFlagRow& row_of(const std::string& flag) {
  for (const SceneFlagRow& row : scene_flag_rows())
    if (row.flag == flag) return row;
  throw std::logic_error("no scene flag row " + flag);
}

std::string joined(const std::vector<std::string>& values) {
  std::string text;
  for (const std::string& v : values) text += (text.empty() ? "" : ",") + v;
  return text;
}

// The setting a given flag stands for, and how a message names it.
NamedSceneSetting setting_of(const SceneFlagRow& row, const std::vector<std::string>& values) {
  switch (row.takes) {
    case SceneFlagRow::Takes::nothing:
      return {row.key + "=" + row.switch_value, row.flag};
    case SceneFlagRow::Takes::list:
      return {row.key + "=[" + joined(values) + "]", row.flag + " " + joined(values)};
    case SceneFlagRow::Takes::value:
      break;
  }
  return {row.key + "=" + (values.empty() ? std::string() : values.front()), row.flag + " " + (values.empty() ? std::string() : values.front())};
}

}  // namespace

void SceneOverrides::give(const std::string& flag, std::vector<std::string> values) {
  row_of(flag);  // a flag with no row is a programming error
  given[flag] = std::move(values);
}

std::vector<NamedSceneSetting> scene_override_settings(const SceneOverrides& o) {
  std::vector<NamedSceneSetting> settings;
  for (const SceneFlagRow& row : scene_flag_rows()) {
    const auto it = o.given.find(row.flag);
    if (it != o.given.end()) settings.push_back(setting_of(row, it->second));
  }
  for (const std::string& setting : o.settings) settings.push_back({setting, "--set " + setting});
  return settings;
}

void add_scene_flag(CLI::App* c, SceneOverrides& o, const std::string& flag, const std::string& help) {
  const SceneFlagRow& row = row_of(flag);
  const std::string& text = help.empty() ? row.help : help;
  switch (row.takes) {
    case SceneFlagRow::Takes::nothing:
      c->add_flag_callback(flag, [&o, flag] { o.given[flag] = {}; }, text);
      break;
    case SceneFlagRow::Takes::list: {
      CLI::Option* option = c->add_option_function<std::vector<std::string>>(flag, [&o, flag](const std::vector<std::string>& v) { o.given[flag] = v; }, text);
      option->delimiter(',');
      if (row.list_length > 0) option->expected(row.list_length);
      break;
    }
    case SceneFlagRow::Takes::value:
      c->add_option_function<std::string>(flag, [&o, flag](const std::string& v) { o.given[flag] = {v}; }, text);
      break;
  }
}

void add_scene_override_options(CLI::App* c, SceneOverrides& o) {
  std::string levels;
  for (const ModelLevel& level : model_levels()) levels += fmt::format("{}{}: {}", levels.empty() ? "" : "; ", level.name, level.description);
  c->add_option("--model", o.model, fmt::format("The model level ({}; default: the scene's; the run defaults' fast)", levels));
  c->add_option("--set", o.settings,
                "Set any scene key, KEY=VALUE with the scene file's dotted names and units, e.g. --set tissue.material.nu=0.49 "
                "--set 'motion.travel=10 mm' (docs/scenes.md); repeatable, applied after the other flags");
  for (const SceneFlagRow& row : scene_flag_rows())
    if (row.flag != "--mesh-size-mm") add_scene_flag(c, o, row.flag);
}

std::string scene_override_arguments(const SceneOverrides& o) {
  std::string line;
  if (!o.model.empty()) line += fmt::format(" --model {}", o.model);
  for (const std::string& setting : o.settings) line += fmt::format(" --set '{}'", setting);
  for (const SceneFlagRow& row : scene_flag_rows()) {
    const auto it = o.given.find(row.flag);
    if (it == o.given.end()) continue;
    line += " " + row.flag;
    if (row.takes != SceneFlagRow::Takes::nothing) line += " " + joined(it->second);
  }
  return line;
}

}  // namespace needle
