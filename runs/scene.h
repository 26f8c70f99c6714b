#pragma once
// A simulation scene: every parameter of the paper scene (shared/SPEC.md), with the paper's values as
// defaults, read from JSON. Keys carry their unit ("travel_mm": 30); a key without its unit suffix
// takes a string with a unit ("travel": "3 cm"); a bare number where a unit is needed, an unknown
// key, or an unphysical value is refused with the file, line and key (docs/scenes.md).
#include <Eigen/Dense>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mesher/needle_mesher.h"
#include "mesher/particle_lattice.h"
#include "solver/needle/insertion_profile.h"
#include "solver/insertion/cannula_firing.h"
#include "solver/insertion/coupled_insertion.h"
#include "solver/separation/separation_models.h"
#include "solver/tissue/spg_options.h"
#include "solver/needle/needle_material.h"
#include "solver/needle/needle_models.h"
#include "solver/needle/rigid_cannula.h"
#include "solver/tissue/tissue_material.h"

namespace needle {

struct NeedleScene {
  // Exactly one source; none given means the paper's SB preset.
  std::string preset, recipe_file, mesh_file;
  double d_a_mm = std::nan("");
  bool plain_rod = false;
  double length_mm = 40.0;  // modelled length from tip point A back to the driven base plane
  // The groove's front wall this far behind A (the paper does not give it); NaN: the recipe's (the presets' 3 mm).
  double groove_start_mm = std::nan("");
  bool half_model = true;   // z >= 0 half with a symmetry plane (paper)
  NeedleMeshOptions mesh;   // T10, 0.2 mm (paper)
  NeedleMaterial material;  // AISI 304
  std::string model = default_needle_model().name;  // a registered needle model (solver/needle/needle_models.h)

  // Makes exactly one of these the needle's source (the others, a mesh file and a plain rod cleared).
  void select_source(const std::string& preset_name, double d_a, const std::string& recipe) {
    preset = preset_name;
    d_a_mm = d_a;
    recipe_file = recipe;
    mesh_file.clear();
    plain_rod = false;
  }
};

struct TissueScene {
  bool enabled = false;                     // false: the needle and cannula alone (needle simulate)
  Eigen::Vector3d size_mm{40.0, 8.0, 2.0};  // x from entry_x, y centred on the axis, z from the symmetry plane
  double entry_x_mm = 0.0;                  // the block's entry face (tip point A starts at x = 0)
  double offset_y_mm = 0.0;                 // the block and its lattice shifted across the path: the lattice's phase in y
  double spacing_mm = 0.4, dilation = 1.8, friction = 0.18;
  // Finer particles around the needle's path (y = z = 0), over the block's whole length: within
  // |y| <= path_half_width_mm and |z| <= path_half_width_mm the spacing is spacing_mm / path_refinement
  // (1: a uniform lattice). The tip's facets are a few tenths of a millimetre high; the paper's 0.4 mm
  // particles put one particle row on LMB's bottom bevel.
  int path_refinement = 1;
  double path_half_width_mm = 1.2;
  // tensor: the fine x intervals run through the whole block (the reference); nested: only the band around the path
  // is fine, the rest coarse along every axis (mesher/particle_lattice.h: LatticeGrading).
  LatticeGrading path_grading = LatticeGrading::tensor;
  TissueMaterial material;
  SpgOptions spg;                           // kernel, stabilization, bond failure, cfl (docs/solver.md)
  ContactOptions contact;                   // friction copied from `friction`
  // The needle's cut, slit, crack and lip (section tissue.separation: needle_cut, slit, crack, lip; until 2026-11-28
  // keys of the contact section, still read: runs/scene_key_spellings.h). A scene crushes the lip below a ground tip
  // point by default (since 2026-11-27, docs/notebook/lip_release.md); the solver's own default leaves it off.
  SeparationOptions separation = scene_separation_defaults();
  CuttingOptions cutting;                   // the cost of cutting on the tip facets (section tissue.cutting: pressure_MPa)
};

struct SolverScene {
  double courant = 0.9;
  double mass_scaling_dt_ms = 0.0;  // 0: off
  double max_energy_error = 0.05;
  double max_penetration_mm = 0.05;
  double implicit_needle_step_ms = 0.0;  // the implicit needle's step (needle.model implicit); 0: about half the tissue's first stable step
  // The tissue's selective mass scaling (solver/tissue/tissue_mass_scaling.h): on when the flag is set or a step
  // is given; the step 0 means the coupling's own: the implicit needle's step (an explicit needle: half the
  // tissue's first stable step).
  bool tissue_mass_scaling = false;
  double tissue_mass_scaling_dt_ms = 0.0;
  int threads = 0;
  CouplingOptions coupling;  // subcycling, step caps, the insertion's stop criteria
};

struct OutputScene {
  double history_interval_ms = 0.01;
  int frames = 20;  // ParaView frames over the run (plus the start)
};

struct Scene {
  std::string source;  // the file it came from
  std::vector<std::string> notes;  // what its reader read but would have the file say otherwise (an older key's spelling)
  NeedleScene needle;
  InsertionProfile motion;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  CannulaOptions cannula;
  CannulaFiringOptions cannula_firing;  // section cannula.firing: the cannula fired over the groove after the travel
  TissueScene tissue;
  SolverScene solver;
  OutputScene output;
};

// InputError with file, line and key for anything wrong.
Scene read_scene(const std::string& path);
// A run folder's scene.json: the effective scene its day's code wrote, every key it knew. A key written only since its
// default changed stands, when absent, for the model before: no cut by the needle (tissue.contact.cuts_bonds), the
// lip below the tip point kept (lip_release_mode, since 2026-11-27) and, released, released whole (lip_release_depth_mm,
// since 2026-11-28). The paper report reads stored runs so.
Scene read_run_scene(const std::string& path);
Scene parse_scene(const std::string& text, const std::string& source);

// The effective scene, every key with its canonical unit suffix; reading it back gives the same scene.
nlohmann::json scene_to_json(const Scene& scene);

// The scene with keys set on the command line, each "section.key=value": dotted scene keys, units as in scene
// files (tissue.material.E_MPa=0.1, motion.travel=3 cm). The value is read as JSON where it parses as such
// (numbers, true/false, [lists]) and as text otherwise (SB, stiffening_elastic, 3 cm). Setting one of a key's
// forms replaces the other (travel replaces travel_mm), and one needle source replaces the other. The scene
// reader checks the result: anything it refuses (an unknown key, a bad value) is an InputError naming --set.
// source names the settings in messages ("--set"; empty: the settings alone, as a study file's keys).
Scene apply_scene_settings(const Scene& scene, const std::vector<std::string>& settings, const std::string& source = "--set");

// One setting and how a message names it: a command's convenience flag ("--travel-mm 5") is the setting
// motion.travel_mm=5 of its row (apps/scene_overrides.cpp), read and checked as --set is.
struct NamedSceneSetting {
  std::string setting;  // key=value
  std::string shown;    // "--travel-mm 5"
};
// As above, the settings read together (the reader checks them as one scene); an InputError names the settings whose
// key its message names (all of them if it names none).
Scene apply_named_scene_settings(const Scene& scene, const std::vector<NamedSceneSetting>& settings);

}  // namespace needle
