#pragma once
// A grinding recipe: a rod, an ordered list of plane grinds and an optional groove, in the
// conventions of shared/SPEC.md (x along the axis toward the tip, y toward the groove, z normal to
// the symmetry plane; a grind tilts the rod by tilt_deg, turns it about its axis by rotation_deg and
// grinds a plane whose outward normal is n = (sin t, cos t cos r, cos t sin r)).
#include <optional>
#include <string>
#include <vector>

namespace needle {

struct Rod {
  double diameter_mm = 1.0;  // 18 G
  double length_mm = 40.0;   // from tip point A back to the base plane
};

// Where a grinding plane sits. Either it passes through the tip point A, or it is ground to a depth:
// in the cross-section x = 0 of the blank, the plane's trace lies depth_mm inside the rod surface,
// measured from the surface point in the facet's direction (cos r, sin r) toward the axis.
struct Grind {
  std::string name;
  double tilt_deg = 0.0;      // angle between the ground plane and the rod axis, in (0, 90)
  double rotation_deg = 0.0;  // about the rod axis; 0 faces +y (groove side), +90 faces +z
  bool through_tip = true;
  double depth_mm = 0.0;      // used when !through_tip, in (0, diameter]
};

// Axis-parallel slot ground with the rod tilted back to 0 degrees: removes y > floor over a length.
struct Groove {
  double length_mm = 22.0;
  double remaining_thickness_mm = 0.43;  // rod material left below the groove floor
  double start_behind_tip_mm = 3.0;      // distance from A (along -x) to the groove's front wall
};

// How finely the smooth rod is approximated by triangles; each choice trades accuracy for speed.
struct TessellationOptions {
  // Largest distance between the polygonal rod surface and the true cylinder, mm.
  double chord_tolerance_mm = 1.0e-3;
  // Axial spacing of the rod's vertex rings near the tip, where the facets cut, mm.
  double axial_spacing_mm = 0.25;
  // Axial spacing of the rings along the rest of the shaft (the groove and behind), mm.
  double shaft_axial_spacing_mm = 1.0;
  // Fewest polygon edges between two consecutive facet corners on the cylinder (keeps small
  // facets' curved edges accurate).
  int min_segments_per_arc = 24;
};

struct GrindingRecipe {
  std::string name = "custom";
  Rod rod;
  std::vector<Grind> grinds;
  std::optional<Groove> groove = Groove{};
  // Tip point A target for through-tip grinds: y of A. Set from d_a by the factory functions.
  std::optional<double> tip_y_mm;
  TessellationOptions tessellation;
};

// Angles of a multi-bevel tip; defaults are the paper's (Section II.B).
struct MultiBevelAngles {
  double top_tilt_deg = 23.5;
  double bevel_tilt_deg = 12.0;
  double side_rotation_deg = 110.0;
};

// SB lancet angles (the paper does not give them; see docs/geometry.md for the reasoning).
struct LancetAngles {
  double tilt_deg = 35.0;
  double rotation_deg = 60.0;
};

// y of the groove floor (the "groove face") for a rod and groove.
double groove_floor_y_mm(const Rod& rod, const Groove& groove);

// A multi-bevel tip: top, bottom and two side facets all through A, with y(A) = floor + d_a.
GrindingRecipe multi_bevel_recipe(double d_a_mm, const MultiBevelAngles& angles = {},
                                  const Rod& rod = {}, const Groove& groove = {});

// The single-bevel (SB) tip: top bevel through the rod's bottom point, plus two lancets through it.
GrindingRecipe single_bevel_recipe(const LancetAngles& lancets = {}, double top_tilt_deg = 23.5,
                                   const Rod& rod = {}, const Groove& groove = {});

// The paper's presets: "SB", "LMB" (d_a -0.22), "AMB" (0), "HMB" (+0.37). Unknown name: InputError.
GrindingRecipe preset_recipe(const std::string& name);
std::vector<std::string> preset_names();

// Checks every number of a recipe for physical sense; throws InputError with one clear message.
void validate_recipe(const GrindingRecipe& recipe);

}  // namespace needle
