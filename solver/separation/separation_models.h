#pragma once
// The separation models a scene asks for, as the list the coupled insertion applies after each step, in
// this order: the needle's cut, the symmetry slit, the tip's crack, the lip's release. Each is one file implementing
// SeparationModel (separation_model.h) and one line in separation_models.cpp.
#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

#include "solver/contact/contact_surface.h"
#include "solver/separation/separation_model.h"
#include "solver/separation/lip_release.h"
#include "solver/separation/symmetry_slit.h"
#include "solver/separation/tip_crack.h"

namespace needle {

// Scene keys: the section tissue.separation mirrors this struct (needle_cut; slit.half_height_mm, slit.lead_mm;
// crack.reach_mm, crack.angles_deg, crack.lead_mm; lip.mode, lip.below_mm, lip.depth_mm). Until 2026-11-28 scenes wrote
// them in tissue.contact with a prefix (cuts_bonds, crack_reach_mm, lip_release_mode, ...), still read
// (runs/scene_key_spellings.h).
struct SeparationOptions {
  bool needle_cut = true;   // the needle breaks the tissue bonds its body passes through (needle_bond_cut.h);
                            // false: only the tissue's failure criterion separates particles
  SymmetrySlitOptions slit;  // the tissue also opens in the symmetry plane behind the tip; off by default
  TipCrackOptions crack;     // the tip drives a crack past the rod's outline; off by default
  LipReleaseOptions lip;     // the lip below tip point A crushed or cut loose; off here, crushed kSceneCrushedLipDepthMm deep in a scene
  void validate(const std::string& where = "separation") const;  // InputError naming the bad field
};

// The depth below tip point A to which a scene crushes the lip (since 2026-11-28). It is fitted to a needle: on HMB
// alone (the needle whose 0.80 mm lip spans every depth studied), the one parameter besides E that the paper's needles
// fit; the others are predicted (docs/notebook/crushed_depth.md; the fit's record, with its leave-one-needle-out
// errors, is data/paper/crushed_depth_hmb.json, and the paper report names it). A lip thinner than this (SB, LMB, AMB)
// is crushed whole.
constexpr double kSceneCrushedLipDepthMm = 0.48;

// A scene's defaults: SeparationOptions{} with the lip below the tip point crushed to kSceneCrushedLipDepthMm
// (lip_release.h).
SeparationOptions scene_separation_defaults();

// The models options switch on, for the needle whose surface is given (they keep a reference to it).
std::vector<std::unique_ptr<SeparationModel>> make_separation_models(const SeparationOptions& options, const ContactSurface& surface);

}  // namespace needle
