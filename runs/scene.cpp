#include "runs/scene.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <fmt/format.h>

#include "runs/json_lines.h"
#include "runs/material_json.h"
#include "runs/scene_object.h"
#include "runs/scene_key_spellings.h"
#include "core/input_error.h"
#include "core/units.h"
#include "solver/contact/contact_laws.h"
#include "solver/needle/needle_models.h"

namespace needle {
namespace {

ValueCheck friction_coefficient() {
  return [](double v) {
    return v >= 0 && v <= kMaxFrictionCoefficient
               ? std::string()
               : fmt::format("must lie in [0, {:g}] (a friction coefficient; the paper's 0.18)", kMaxFrictionCoefficient);
  };
}

using nlohmann::json;

void read_needle(SceneObject o, NeedleScene& n, const std::string& scene_folder) {
  n.preset = o.text("preset", "");
  n.d_a_mm = o.quantity("d_a", Dimension::length, n.d_a_mm, any_finite());
  n.recipe_file = o.text("recipe", "");
  n.mesh_file = o.text("mesh_file", "");
  n.plain_rod = o.boolean("plain_rod", false);
  const int sources = !n.preset.empty() + !std::isnan(n.d_a_mm) + !n.recipe_file.empty() + !n.mesh_file.empty() + n.plain_rod;
  NEEDLE_REQUIRE(sources <= 1, fmt::format("{}: give one of preset, d_a_mm, recipe, mesh_file or plain_rod", o.where("preset")));
  if (sources == 0) n.preset = "SB";
  for (std::string* file : {&n.recipe_file, &n.mesh_file}) {
    if (file->empty()) continue;
    const std::string key = file == &n.recipe_file ? "recipe" : "mesh_file";
    std::filesystem::path p(*file);
    if (p.is_relative()) p = std::filesystem::path(scene_folder) / p;
    NEEDLE_REQUIRE(std::filesystem::is_regular_file(p), fmt::format("{}: file '{}' does not exist", o.where(key), p.string()));
    *file = p.string();
  }
  n.length_mm = o.quantity("length", Dimension::length, n.length_mm, positive());
  n.groove_start_mm = o.quantity("groove_start", Dimension::length, n.groove_start_mm, positive());
  NEEDLE_REQUIRE(std::isnan(n.groove_start_mm) || (n.mesh_file.empty() && !n.plain_rod),
                 fmt::format("{}: a groove start moves the groove of a ground tip (a preset, d_a_mm or a recipe), not of a plain "
                             "rod or a mesh file", o.where("groove_start_mm")));
  n.half_model = o.boolean("half_model", n.half_model);
  if (o.has("mesh")) {
    SceneObject m = o.child("mesh");
    n.mesh.order = m.integer("order", n.mesh.order, 1, 2);
    n.mesh.size_mm = m.quantity("size", Dimension::length, n.mesh.size_mm, positive());
    n.mesh.tip_size_mm = m.quantity("tip_size", Dimension::length, n.mesh.tip_size_mm, non_negative());
    n.mesh.edge_size_mm = m.quantity("edge_size", Dimension::length, n.mesh.edge_size_mm, non_negative());
    n.mesh.shaft_size_mm = m.quantity("shaft_size", Dimension::length, n.mesh.shaft_size_mm, non_negative());
    n.mesh.grading_mm = m.quantity("grading", Dimension::length, n.mesh.grading_mm, positive());
    m.finish();
    try {
      n.mesh.resolved();
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: {}", o.where("mesh"), e.what()));
    }
  }
  if (o.has("material")) {
    SceneObject m = o.child("material");
    n.material.youngs_modulus_MPa = m.quantity("youngs_modulus", Dimension::stress, n.material.youngs_modulus_MPa, positive());
    n.material.poisson_ratio = m.number("poisson_ratio", n.material.poisson_ratio, within(-0.999, 0.499));
    n.material.density_g_per_mm3 = m.quantity("density", Dimension::density, n.material.density_g_per_mm3, positive());
    m.finish();
  }
  // needle.model names a registered needle model (solver/needle/needle_models.h); a model's legacy key (rigid: true) is
  // the older way to select it, and contradicts any other model named beside it but the default.
  n.model = o.text("model", n.model);
  needle_model(n.model, o.where("model"));  // refuses an unknown name with the file and line
  for (const NeedleModelEntry& m : needle_models()) {
    if (m.legacy_key.empty() || !o.boolean(m.legacy_key, n.model == m.name)) continue;
    NEEDLE_REQUIRE(n.model == default_needle_model().name || n.model == m.name,
                   fmt::format("{}: {}: true contradicts model '{}'", o.where(m.legacy_key), m.legacy_key, n.model));
    n.model = m.name;
  }
  o.finish();
}

// A drive's speed: positive and at most InsertionProfile::kMaxSpeedMPerS (beyond it a typo); `typical` says what is usual.
ValueCheck drive_speed(const std::string& typical) {
  return [typical](double v) {
    return v > 0 && v <= InsertionProfile::kMaxSpeedMPerS
               ? std::string()
               : fmt::format("must be positive and at most {:g} m/s ({})", InsertionProfile::kMaxSpeedMPerS, typical);
  };
}

void read_motion(SceneObject o, Scene& s) {
  InsertionProfile& p = s.motion;
  p.accel_time_ms = o.quantity("accel_time", Dimension::time, p.accel_time_ms, non_negative());
  p.speed_mm_per_ms = o.quantity("speed", Dimension::speed, p.speed_mm_per_ms, drive_speed("the paper's drive: 8 m/s"));
  p.travel_mm = o.quantity("travel", Dimension::length, p.travel_mm, positive());
  p.decel_time_ms = o.quantity("decel_time", Dimension::time, p.decel_time_ms, non_negative());
  p.hold_ms = o.quantity("hold", Dimension::time, p.hold_ms, non_negative());
  s.direction = o.vector3("direction", s.direction);
  NEEDLE_REQUIRE(s.direction.allFinite() && s.direction.norm() > 0, fmt::format("{} must be a non-zero vector", o.where("direction")));
  try {
    p.validate("motion");
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", o.where("travel_mm"), e.what()));
  }
  o.finish();
}

void read_cannula_firing(SceneObject o, CannulaFiringOptions& f) {
  f.enabled = o.boolean("enabled", f.enabled);
  f.speed_mm_per_ms = o.quantity("speed", Dimension::speed, f.speed_mm_per_ms, drive_speed("the paper's device: about 4 m/s"));
  f.throw_mm = o.quantity("throw", Dimension::length, f.throw_mm, positive());
  f.dwell_ms = o.quantity("dwell", Dimension::time, f.dwell_ms, non_negative());
  f.lead_in_mm = o.quantity("lead_in", Dimension::length, f.lead_in_mm, non_negative());
  f.edge_taper_mm = o.quantity("edge_taper", Dimension::length, f.edge_taper_mm, non_negative());
  f.tissue_mass_scaling_dt_ms = o.quantity("tissue_mass_scaling_dt", Dimension::time, f.tissue_mass_scaling_dt_ms, non_negative());
  o.finish();
}

void read_cannula(SceneObject o, CannulaOptions& c, CannulaFiringOptions& firing) {
  c.enabled = o.boolean("enabled", c.enabled);
  c.outer_diameter_mm = o.quantity("outer_diameter", Dimension::length, c.outer_diameter_mm, positive());
  c.wall_mm = o.quantity("wall", Dimension::length, c.wall_mm, positive());
  c.front_x_mm = o.quantity("front_x", Dimension::length, c.front_x_mm, any_finite());
  c.length_mm = o.quantity("length", Dimension::length, c.length_mm, positive());
  c.friction = o.number("friction", c.friction, friction_coefficient());
  c.penalty_scale = o.number("penalty_scale", c.penalty_scale, within(1e-6, 0.5));
  NEEDLE_REQUIRE(c.wall_mm < 0.5 * c.outer_diameter_mm, fmt::format("{}: the wall leaves no bore", o.where("wall_mm")));
  if (o.has("firing")) read_cannula_firing(o.child("firing"), firing);
  o.finish();
}

// The separation models' keys, each named prefix + its name: in its own section (no prefix) or in the contact section as
// scenes wrote them until 2026-11-28 ("slit_", "crack_", "lip_release_").
void read_slit(SceneObject& o, const std::string& prefix, SymmetrySlitOptions& slit) {
  slit.half_height_mm = o.quantity(prefix + "half_height", Dimension::length, slit.half_height_mm, non_negative());
  slit.lead_mm = o.quantity(prefix + "lead", Dimension::length, slit.lead_mm, non_negative());
}

void read_crack(SceneObject& o, const std::string& prefix, TipCrackOptions& crack) {
  crack.reach_mm = o.quantity(prefix + "reach", Dimension::length, crack.reach_mm, non_negative());
  crack.angles_deg = o.numbers(prefix + "angles_deg", crack.angles_deg, within(-180.0, 180.0));
  crack.lead_mm = o.quantity(prefix + "lead", Dimension::length, crack.lead_mm, non_negative());
}

void read_lip(SceneObject& o, const std::string& prefix, LipReleaseOptions& lip) {
  // The band's depth: a length, or "whole lip" (down to the rod's bottom, however thick the lip).
  const std::string depth_key = prefix + "depth_mm";
  if (o.has(depth_key) && o.raw(depth_key).is_string()) {
    const std::string depth = o.raw(depth_key).get<std::string>();
    NEEDLE_REQUIRE(depth == kWholeLipText, fmt::format("{}: give a depth in mm or \"{}\" (got \"{}\")", o.where(depth_key), kWholeLipText, depth));
    lip.depth_mm = std::numeric_limits<double>::infinity();
  } else {
    lip.depth_mm = o.quantity(prefix + "depth", Dimension::length, lip.depth_mm, positive());
  }
  lip.below_mm = o.quantity(prefix + "below", Dimension::length, lip.below_mm, non_negative());
  const std::string mode = o.text(prefix + "mode", lip_release_mode_name(lip.mode));
  try {
    lip.mode = lip_release_mode_from_name(mode);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", o.where(prefix + "mode"), e.what()));
  }
}

void read_cutting(SceneObject& o, const std::string& prefix, CuttingOptions& c) {
  c.pressure_MPa = o.quantity(prefix + "pressure", Dimension::stress, c.pressure_MPa, non_negative());
}

// The first of these JSON pointers the document holds (the last if none), and the dotted key it names.
std::string first_given(const JsonDocument& doc, const std::vector<std::string>& pointers) {
  for (const std::string& p : pointers)
    if (doc.value.contains(json::json_pointer(p))) return p;
  return pointers.back();
}
std::string key_name(const std::string& pointer) {
  std::string key = pointer.substr(1);
  std::replace(key.begin(), key.end(), '/', '.');
  return key;
}

// The separation's and cutting's keys written in the contact section the older way: read as their sections' keys, with
// a note each; given in both places they are refused.
void read_older_contact_keys(SceneObject& c, const JsonDocument& doc, TissueScene& t, std::vector<std::string>& notes) {
  for (const auto& item : doc.value.at(json::json_pointer("/tissue/contact")).items()) {
    const std::optional<KeySpelling> now = current_contact_key(item.key());
    if (!now) continue;
    std::string section = "/tissue/" + now->section;
    std::replace(section.begin(), section.end(), '.', '/');
    // Any spelling of the same quantity in its section: "reach_mm" or "reach".
    if (doc.value.contains(json::json_pointer(section)) && doc.value.at(json::json_pointer(section)).is_object())
      for (const auto& given : doc.value.at(json::json_pointer(section)).items()) {
        const std::string pointer = section + "/" + json_pointer_token(given.key());
        NEEDLE_REQUIRE(key_quantity(given.key()) != now->quantity,
                       fmt::format("{}: give {} or tissue.contact.{} (its older spelling), not both", doc.where(pointer), key_name(pointer), item.key()));
      }
    notes.push_back(older_spelling_note(doc.where("/tissue/contact/" + json_pointer_token(item.key())), "tissue.contact." + item.key(),
                                        "tissue." + now->section + "." + now->key));
  }
  t.separation.needle_cut = c.boolean("cuts_bonds", t.separation.needle_cut);
  read_slit(c, "slit_", t.separation.slit);
  read_crack(c, "crack_", t.separation.crack);
  read_lip(c, "lip_release_", t.separation.lip);
  read_cutting(c, "cutting_", t.cutting);
}

void read_tissue(SceneObject o, TissueScene& t, const JsonDocument& doc, std::vector<std::string>& notes) {
  t.enabled = o.boolean("enabled", t.enabled);
  t.size_mm = o.vector3("size_mm", t.size_mm);
  NEEDLE_REQUIRE((t.size_mm.array() > 0).all(), fmt::format("{} must be three positive lengths", o.where("size_mm")));
  t.entry_x_mm = o.quantity("entry_x", Dimension::length, t.entry_x_mm, non_negative());
  t.offset_y_mm = o.quantity("offset_y", Dimension::length, t.offset_y_mm, any_finite());
  t.spacing_mm = o.quantity("spacing", Dimension::length, t.spacing_mm, positive());
  t.path_refinement = o.integer("path_refinement", t.path_refinement, 1, 8);
  t.path_half_width_mm = o.quantity("path_half_width", Dimension::length, t.path_half_width_mm, positive());
  {
    const double bound = lattice_particle_bound(t.size_mm, t.spacing_mm, t.path_refinement);
    NEEDLE_REQUIRE(bound < kMaxLatticeParticles,
                   fmt::format("{}: {} mm particles (refined {} times near the path) in a block of {} x {} x {} mm would make up to {:.3g} "
                               "particles (limit {:.0e})",
                               o.where("spacing_mm"), t.spacing_mm, t.path_refinement, t.size_mm.x(), t.size_mm.y(), t.size_mm.z(), bound,
                               kMaxLatticeParticles));
  }
  {
    const std::string grading = o.text("path_grading", lattice_grading_name(t.path_grading));
    try {
      t.path_grading = lattice_grading_from_name(grading);
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: {}", o.where("path_grading"), e.what()));
    }
  }
  t.dilation = o.number("dilation", t.dilation, within(1.0, 4.0));
  t.spg.dilation = t.dilation;
  t.friction = o.number("friction", t.friction, friction_coefficient());
  t.contact.friction = t.friction;
  if (o.has("material")) {
    t.material = material_from_json(o.raw("material"), doc.where("/tissue/material"), t.material);
    // A relaxation time alone would be dropped from scene.json without a word (the card has no relaxation).
    NEEDLE_REQUIRE(!o.raw("material").contains("relaxation_time_ms") || t.material.viscoelastic(),
                   fmt::format("{}: tissue.material.relaxation_time_ms needs a relaxing_shear_fraction above 0 (the share of the shear "
                               "stress that relaxes)", doc.where("/tissue/material/relaxation_time_ms")));
  }
  t.material.validate();
  if (o.has("spg")) {
    SceneObject g = o.child("spg");
    const auto name = [&](const std::string& key, const std::string& fallback, auto parse) {
      const std::string value = g.text(key, fallback);
      try {
        return parse(value);
      } catch (const InputError& e) {
        throw InputError(fmt::format("{}: {}", g.where(key), e.what()));
      }
    };
    t.spg.support = name("support", support_shape_name(t.spg.support), support_shape_from_name);
    t.spg.kernel_update = name("kernel_update", kernel_update_name(t.spg.kernel_update), kernel_update_from_name);
    t.spg.kernel_update_interval_steps = g.integer("kernel_update_interval_steps", t.spg.kernel_update_interval_steps, 1, 1000000);
    t.spg.stabilization = name("stabilization", stabilization_name(t.spg.stabilization), stabilization_from_name);
    t.spg.stabilization_coefficient = g.number("stabilization_coefficient", t.spg.stabilization_coefficient, within(0.0, 10.0));
    t.spg.smoothing_interval_steps = g.integer("smoothing_interval_steps", t.spg.smoothing_interval_steps, 1, 1000000);
    t.spg.bond_failure.enabled = g.boolean("bond_failure", t.spg.bond_failure.enabled);
    t.spg.bond_failure.measure = name("failure_measure", failure_measure_name(t.spg.bond_failure.measure), failure_measure_from_name);
    t.spg.bond_failure.strain = g.number("failure_strain", t.spg.bond_failure.strain, positive());
    t.spg.bond_failure.stretch_ratio = g.number("failure_stretch_ratio", t.spg.bond_failure.stretch_ratio, non_negative());
    t.spg.crack_face_min_volume_ratio = g.number("crack_face_min_volume_ratio", t.spg.crack_face_min_volume_ratio, within(0.0, 0.99));
    t.spg.cfl = g.number("cfl", t.spg.cfl, within(1e-3, 1.0));
    g.finish();
  }
  // The separation models and the cost of cutting: in sections that mirror their structs, or, as scenes wrote them
  // until 2026-11-28, in the contact section with a prefix (runs/scene_key_spellings.h), read so with a note.
  if (o.has("separation")) {
    SceneObject sep = o.child("separation");
    t.separation.needle_cut = sep.boolean("needle_cut", t.separation.needle_cut);
    const auto section = [&sep](const char* name, const auto& read) {
      if (!sep.has(name)) return;
      SceneObject m = sep.child(name);
      read(m);
      m.finish();
    };
    section("slit", [&t](SceneObject& m) { read_slit(m, "", t.separation.slit); });
    section("crack", [&t](SceneObject& m) { read_crack(m, "", t.separation.crack); });
    section("lip", [&t](SceneObject& m) { read_lip(m, "", t.separation.lip); });
    sep.finish();
  }
  if (o.has("cutting")) {
    SceneObject c = o.child("cutting");
    read_cutting(c, "", t.cutting);
    c.finish();
  }
  if (o.has("contact")) {
    SceneObject c = o.child("contact");
    t.contact.law = c.text("law", t.contact.law);
    contact_law(t.contact.law, c.where("law"));  // InputError for an unknown law
    t.contact.stiffness_factor = c.number("stiffness_factor", t.contact.stiffness_factor, within(1e-3, 1e4));
    t.contact.skin_mm = c.quantity("skin", Dimension::length, t.contact.skin_mm, non_negative());
    t.contact.voxel_mm = c.quantity("voxel", Dimension::length, t.contact.voxel_mm, within(1e-3, 0.2));
    t.contact.damping_ratio = c.number("damping_ratio", t.contact.damping_ratio, within(0.0, 1.0));
    t.contact.needle_stiffness_scale = c.number("needle_stiffness_scale", t.contact.needle_stiffness_scale, within(1e-6, 0.5));
    read_older_contact_keys(c, doc, t, notes);
    c.finish();
  }
  // The crack's shape without a crack would be dropped from scene.json without a word.
  if (!t.separation.crack.enabled() &&
      (t.separation.crack.angles_deg != TipCrackOptions{}.angles_deg || t.separation.crack.lead_mm != TipCrackOptions{}.lead_mm)) {
    const std::string pointer = first_given(doc, {"/tissue/separation/crack/angles_deg", "/tissue/separation/crack/lead_mm",
                                                  "/tissue/separation/crack/lead", "/tissue/contact/crack_angles_deg",
                                                  "/tissue/contact/crack_lead_mm", "/tissue/contact/crack_lead"});
    throw InputError(fmt::format("{}: {}: the crack's shape (its angles and lead) needs a crack: tissue.separation.crack.reach_mm above 0",
                                 doc.where(pointer), key_name(pointer)));
  }
  // A shifted block keeps the path (y = z = 0) inside it, with a rod's radius to spare.
  NEEDLE_REQUIRE(t.offset_y_mm == 0 || std::abs(t.offset_y_mm) + 0.5 < 0.5 * t.size_mm.y(),
                 fmt::format("{}: {} mm moves the block's side faces within a rod's radius of the path (size_mm y {} mm)",
                             o.where("offset_y_mm"), t.offset_y_mm, t.size_mm.y()));
  o.finish();
}

void read_solver(SceneObject o, SolverScene& s) {
  s.courant = o.number("courant", s.courant, within(1e-3, 1.0));
  s.mass_scaling_dt_ms = o.quantity("mass_scaling_dt", Dimension::time, s.mass_scaling_dt_ms, non_negative());
  s.max_energy_error = o.number("max_energy_error", s.max_energy_error, positive());
  s.max_penetration_mm = o.quantity("max_penetration", Dimension::length, s.max_penetration_mm, positive());
  s.implicit_needle_step_ms = o.quantity("implicit_needle_step", Dimension::time, s.implicit_needle_step_ms, within(0.0, 0.1));
  s.threads = o.integer("threads", s.threads, 0, 1024);
  s.tissue_mass_scaling = o.boolean("tissue_mass_scaling", s.tissue_mass_scaling);
  s.tissue_mass_scaling_dt_ms = o.quantity("tissue_mass_scaling_dt", Dimension::time, s.tissue_mass_scaling_dt_ms, within(0.0, 0.1));
  CouplingOptions& c = s.coupling;
  c.subcycling = o.boolean("subcycling", c.subcycling);
  c.max_step_ms = o.quantity("max_coupling_step", Dimension::time, c.max_step_ms, non_negative());
  c.contact_courant = o.number("contact_courant", c.contact_courant, within(1e-3, 1.0));
  c.max_energy_error = s.max_energy_error;
  c.max_depth_mm = o.quantity("max_contact_depth", Dimension::length, c.max_depth_mm, positive());
  c.tissue_beside_needle = o.boolean("tissue_beside_needle", c.tissue_beside_needle);
  c.needle_ahead = o.boolean("needle_ahead", c.needle_ahead);
  c.tissue_ahead_margin_mm = o.quantity("tissue_ahead_margin", Dimension::length, c.tissue_ahead_margin_mm, non_negative());
  c.tissue_rate_levels = o.integer("tissue_rate_levels", c.tissue_rate_levels, 0, 10);
  c.tissue_rate_needle_margin_mm = o.quantity("tissue_rate_needle_margin", Dimension::length, c.tissue_rate_needle_margin_mm, any_finite());
  c.tissue_rate_safety = o.number("tissue_rate_safety", c.tissue_rate_safety, within(1.0, 1e3));
  o.finish();
}

void read_output(SceneObject o, OutputScene& out) {
  out.history_interval_ms = o.quantity("history_interval", Dimension::time, out.history_interval_ms, positive());
  out.frames = o.integer("frames", out.frames, 0, 10000);
  o.finish();
}

// start: the values a key left out takes (Scene{}: the defaults).
Scene scene_from_document(const JsonDocument& doc, Scene s = {}) {
  s.source = doc.source;
  const std::string folder = std::filesystem::path(doc.source).parent_path().string();
  SceneObject root(doc, "", "");
  if (root.has("needle")) read_needle(root.child("needle"), s.needle, folder);
  else s.needle.preset = "SB";
  if (root.has("motion")) read_motion(root.child("motion"), s);
  if (root.has("cannula")) read_cannula(root.child("cannula"), s.cannula, s.cannula_firing);
  if (root.has("tissue")) read_tissue(root.child("tissue"), s.tissue, doc, s.notes);
  if (root.has("solver")) read_solver(root.child("solver"), s.solver);
  if (root.has("output")) read_output(root.child("output"), s.output);
  root.text("description", "");
  root.finish();
  // What one section's keys mean for another's.
  if (s.tissue.separation.slit.enabled() && !s.needle.half_model) {
    const std::string slit = first_given(doc, {"/tissue/separation/slit/half_height_mm", "/tissue/separation/slit/half_height",
                                               "/tissue/contact/slit_half_height_mm", "/tissue/contact/slit_half_height"});
    throw InputError(fmt::format("{}: {}: the slit opens the symmetry plane, so it needs a half model (needle.half_model true)",
                                 doc.where(slit), key_name(slit)));
  }
  NEEDLE_REQUIRE(!s.cannula_firing.enabled || s.tissue.enabled,
                 fmt::format("{}: the cannula is fired over the groove to take a tissue sample: it needs tissue (tissue.enabled true)",
                             doc.where("/cannula/firing/enabled")));
  NEEDLE_REQUIRE(!s.tissue.enabled || s.tissue.entry_x_mm < s.motion.travel_mm,
                 fmt::format("{}: tissue.entry_x_mm {} mm is not less than the travel ({} mm): the tip would never reach the tissue",
                             doc.where("/tissue/entry_x_mm"), s.tissue.entry_x_mm, s.motion.travel_mm));
  return s;
}

json vector_json(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

}  // namespace

Scene parse_scene(const std::string& text, const std::string& source) {
  return scene_from_document(parse_json_with_lines(text, source));
}

Scene read_scene(const std::string& path) { return scene_from_document(read_json_with_lines(path)); }

Scene read_run_scene(const std::string& path) {
  Scene before;
  before.tissue.separation.needle_cut = false;           // tissue.contact.cuts_bonds, written since the needle cuts
  before.tissue.separation.lip = LipReleaseOptions{};  // the lip kept; released, the whole lip (lip_release_mode, _depth_mm)
  return scene_from_document(read_json_with_lines(path), before);
}

json scene_to_json(const Scene& s) {
  const NeedleScene& n = s.needle;
  json needle = {{"length_mm", n.length_mm}, {"half_model", n.half_model}};
  if (!n.preset.empty()) needle["preset"] = n.preset;
  if (!std::isnan(n.d_a_mm)) needle["d_a_mm"] = n.d_a_mm;
  if (!n.recipe_file.empty()) needle["recipe"] = std::filesystem::absolute(n.recipe_file).string();
  if (!n.mesh_file.empty()) needle["mesh_file"] = std::filesystem::absolute(n.mesh_file).string();
  if (n.plain_rod) needle["plain_rod"] = true;
  if (!std::isnan(n.groove_start_mm)) needle["groove_start_mm"] = n.groove_start_mm;
  needle["mesh"] = {{"order", n.mesh.order}, {"size_mm", n.mesh.size_mm}, {"tip_size_mm", n.mesh.tip_size_mm},
                    {"edge_size_mm", n.mesh.edge_size_mm}, {"shaft_size_mm", n.mesh.shaft_size_mm}, {"grading_mm", n.mesh.grading_mm}};
  needle["material"] = {{"youngs_modulus_MPa", n.material.youngs_modulus_MPa}, {"poisson_ratio", n.material.poisson_ratio},
                        {"density_g_per_cm3", internal_to_canonical(Dimension::density, n.material.density_g_per_mm3)}};
  // A model selected by its legacy key is written so (stored scenes read the same); another but the default by name.
  for (const NeedleModelEntry& m : needle_models())
    if (!m.legacy_key.empty()) needle[m.legacy_key] = n.model == m.name;
  if (n.model != default_needle_model().name && needle_model(n.model).legacy_key.empty()) needle["model"] = n.model;
  const TissueScene& t = s.tissue;
  json tissue = {
      {"enabled", t.enabled}, {"size_mm", vector_json(t.size_mm)}, {"entry_x_mm", t.entry_x_mm}, {"spacing_mm", t.spacing_mm},
      {"path_refinement", t.path_refinement}, {"path_half_width_mm", t.path_half_width_mm},
      {"path_grading", lattice_grading_name(t.path_grading)},
      {"dilation", t.dilation}, {"friction", t.friction}, {"material", material_to_json(t.material)},
      {"spg", {{"support", support_shape_name(t.spg.support)},
               {"kernel_update", kernel_update_name(t.spg.kernel_update)},
               {"kernel_update_interval_steps", t.spg.kernel_update_interval_steps},
               {"stabilization", stabilization_name(t.spg.stabilization)},
               {"stabilization_coefficient", t.spg.stabilization_coefficient},
               {"smoothing_interval_steps", t.spg.smoothing_interval_steps},
               {"bond_failure", t.spg.bond_failure.enabled},
               {"failure_measure", failure_measure_name(t.spg.bond_failure.measure)},
               {"failure_strain", t.spg.bond_failure.strain},
               {"failure_stretch_ratio", t.spg.bond_failure.stretch_ratio},
               {"crack_face_min_volume_ratio", t.spg.crack_face_min_volume_ratio},
               {"cfl", t.spg.cfl}}},
      {"contact", {{"stiffness_factor", t.contact.stiffness_factor}, {"skin_mm", t.contact.skin_mm}, {"voxel_mm", t.contact.voxel_mm},
                   {"damping_ratio", t.contact.damping_ratio}, {"needle_stiffness_scale", t.contact.needle_stiffness_scale}}}};
  if (t.offset_y_mm != 0) tissue["offset_y_mm"] = t.offset_y_mm;
  if (t.contact.law != ContactOptions{}.law) tissue["contact"]["law"] = t.contact.law;
  // The separation models as SeparationOptions holds them: the needle's cut always; a slit or a crack only when on.
  // The lip's mode is always written (its default changed on 2026-11-27: a scene says which model made it), and so is
  // a released lip's depth (its default changed on 2026-11-28, from the whole lip to 0.45 mm); the band's top only when
  // it is not at the tip point.
  json separation = {{"needle_cut", t.separation.needle_cut}};
  if (t.separation.slit.enabled())
    separation["slit"] = {{"half_height_mm", t.separation.slit.half_height_mm}, {"lead_mm", t.separation.slit.lead_mm}};
  if (t.separation.crack.enabled())
    separation["crack"] = {{"reach_mm", t.separation.crack.reach_mm}, {"angles_deg", t.separation.crack.angles_deg},
                           {"lead_mm", t.separation.crack.lead_mm}};
  json& lip = separation["lip"] = {{"mode", lip_release_mode_name(t.separation.lip.mode)}};
  if (t.separation.lip.enabled() && t.separation.lip.below_mm != 0) lip["below_mm"] = t.separation.lip.below_mm;
  if (t.separation.lip.enabled()) lip["depth_mm"] = std::isfinite(t.separation.lip.depth_mm) ? json(t.separation.lip.depth_mm) : json(kWholeLipText);
  tissue["separation"] = separation;
  if (t.cutting.enabled()) tissue["cutting"] = {{"pressure_MPa", t.cutting.pressure_MPa}};
  const CannulaOptions& c = s.cannula;
  json motion = {{"accel_time_ms", s.motion.accel_time_ms}, {"speed_m_per_s", s.motion.speed_mm_per_ms}, {"travel_mm", s.motion.travel_mm},
                 {"direction", vector_json(s.direction)}};
  // Written only when used: stored scenes (the paper's model, neither) stay as they were.
  if (s.motion.decel_time_ms > 0) motion["decel_time_ms"] = s.motion.decel_time_ms;
  if (s.motion.hold_ms > 0) motion["hold_ms"] = s.motion.hold_ms;
  json solver = {{"courant", s.solver.courant}, {"mass_scaling_dt_ms", s.solver.mass_scaling_dt_ms},
                 {"max_energy_error", s.solver.max_energy_error}, {"max_penetration_mm", s.solver.max_penetration_mm},
                 {"threads", s.solver.threads}, {"subcycling", s.solver.coupling.subcycling},
                 {"max_coupling_step_ms", s.solver.coupling.max_step_ms}, {"contact_courant", s.solver.coupling.contact_courant},
                 {"max_contact_depth_mm", s.solver.coupling.max_depth_mm}};
  if (needle_model(s.needle.model).takes_coupling_step) solver["implicit_needle_step_ms"] = s.solver.implicit_needle_step_ms;
  if (s.solver.tissue_mass_scaling) solver["tissue_mass_scaling"] = true;
  if (s.solver.tissue_mass_scaling_dt_ms > 0) solver["tissue_mass_scaling_dt_ms"] = s.solver.tissue_mass_scaling_dt_ms;
  // Written only when not the default (the same results either way: a matter of speed).
  const CouplingOptions defaults;
  if (s.solver.coupling.tissue_beside_needle != defaults.tissue_beside_needle) solver["tissue_beside_needle"] = s.solver.coupling.tissue_beside_needle;
  if (s.solver.coupling.needle_ahead != defaults.needle_ahead) solver["needle_ahead"] = s.solver.coupling.needle_ahead;
  if (s.solver.coupling.tissue_ahead_margin_mm != defaults.tissue_ahead_margin_mm)
    solver["tissue_ahead_margin_mm"] = s.solver.coupling.tissue_ahead_margin_mm;
  if (s.solver.coupling.tissue_rate_levels > 0) {  // multi-rate stepping (changes results): written with its margin
    solver["tissue_rate_levels"] = s.solver.coupling.tissue_rate_levels;
    solver["tissue_rate_needle_margin_mm"] = s.solver.coupling.tissue_rate_needle_margin_mm;
    solver["tissue_rate_safety"] = s.solver.coupling.tissue_rate_safety;
  }
  json cannula = {{"enabled", c.enabled},       {"outer_diameter_mm", c.outer_diameter_mm}, {"wall_mm", c.wall_mm},
                 {"front_x_mm", c.front_x_mm}, {"length_mm", c.length_mm},                 {"friction", c.friction},
                 {"penalty_scale", c.penalty_scale}};
  // Written only when fired (issue 50): scenes without it stay as they were.
  if (const CannulaFiringOptions& f = s.cannula_firing; f.enabled) {
    cannula["firing"] = {{"enabled", true},          {"speed_m_per_s", f.speed_mm_per_ms}, {"dwell_ms", f.dwell_ms},
                         {"lead_in_mm", f.lead_in_mm}, {"edge_taper_mm", f.edge_taper_mm}};
    if (!std::isnan(f.throw_mm)) cannula["firing"]["throw_mm"] = f.throw_mm;  // absent: to the groove's far end
    cannula["firing"]["tissue_mass_scaling_dt_ms"] = f.tissue_mass_scaling_dt_ms;
  }
  return {
      {"needle", needle},
      {"motion", motion},
      {"cannula", cannula},
      {"tissue", tissue},
      {"solver", solver},
      {"output", {{"history_interval_ms", s.output.history_interval_ms}, {"frames", s.output.frames}}},
  };
}

Scene apply_scene_settings(const Scene& scene, const std::vector<std::string>& settings, const std::string& source) {
  std::vector<NamedSceneSetting> named;
  for (const std::string& setting : settings) named.push_back({setting, source.empty() ? setting : source + " " + setting});
  return apply_named_scene_settings(scene, named);
}

Scene apply_named_scene_settings(const Scene& scene, const std::vector<NamedSceneSetting>& settings) {
  if (settings.empty()) return scene;
  json j = scene_to_json(scene);
  std::vector<std::string> keys, notes;
  for (const auto& [setting, shown] : settings) {
    const size_t eq = setting.find('=');
    NEEDLE_REQUIRE(eq != std::string::npos && eq > 0, fmt::format("{}: give key=value, e.g. {}", shown, "--set tissue.material.E_MPa=0.1"));
    // A key in an older spelling sets the key it is now (tissue.contact.crack_reach_mm: tissue.separation.crack.reach_mm).
    const std::string given = setting.substr(0, eq), key = current_scene_key(given), value = setting.substr(eq + 1);
    if (key != given) notes.push_back(older_spelling_note(shown, given, key));
    keys.push_back(key);
    std::vector<std::string> path;
    for (size_t start = 0;;) {
      const size_t dot = key.find('.', start);
      path.push_back(key.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
      NEEDLE_REQUIRE(!path.back().empty(), fmt::format("{}: '{}' is not a dotted scene key (docs/scenes.md)", shown, key));
      if (dot == std::string::npos) break;
      start = dot + 1;
    }
    json* section = &j;
    for (size_t k = 0; k + 1 < path.size(); ++k) {
      json& next = (*section)[path[k]];
      if (next.is_null()) next = json::object();
      NEEDLE_REQUIRE(next.is_object(), fmt::format("{}: {} is a value, not a section", shown, path[k]));
      section = &next;
    }
    const std::string& leaf = path.back();
    static const std::vector<std::string> sources = {"preset", "d_a_mm", "d_a", "recipe", "mesh_file", "plain_rod"};
    const bool is_source = path.size() == 2 && path[0] == "needle" && std::find(sources.begin(), sources.end(), leaf) != sources.end();
    for (auto it = section->begin(); it != section->end();) {
      const std::string& other = it.key();
      // The same quantity in another unit spelling only: a longer key that merely begins with this one stays.
      const bool same_key = key_quantity(other) == key_quantity(leaf);
      const bool other_source = is_source && std::find(sources.begin(), sources.end(), other) != sources.end();
      it = (same_key || other_source) && !it.value().is_object() ? section->erase(it) : std::next(it);
    }
    json parsed = json::parse(value, nullptr, false);
    (*section)[leaf] = parsed.is_discarded() ? json(value) : parsed;
  }
  try {
    Scene out = parse_scene(j.dump(2), "--set");
    out.source = scene.source;
    out.notes = scene.notes;
    out.notes.insert(out.notes.end(), notes.begin(), notes.end());
    return out;
  } catch (const InputError& e) {
    // The reader names "--set:LINE: key: problem"; the line is of the generated text, so say what was set instead:
    // the settings whose key (in any unit spelling) the message names, or all of them.
    std::string message = e.what();
    const size_t colon = message.rfind("--set:", 0) == 0 ? message.find(": ") : std::string::npos;
    if (colon != std::string::npos) message = message.substr(colon + 2);
    std::string named, all;
    for (size_t k = 0; k < settings.size(); ++k) {
      all += (all.empty() ? "" : " ") + settings[k].shown;
      const size_t dot = keys[k].rfind('.');
      const std::string quantity = (dot == std::string::npos ? std::string() : keys[k].substr(0, dot + 1)) + key_quantity(keys[k].substr(dot + 1));
      if (message.find(quantity) != std::string::npos) named += (named.empty() ? "" : " ") + settings[k].shown;
    }
    throw InputError(fmt::format("{}: {}", named.empty() ? all : named, message));
  }
}

}  // namespace needle
