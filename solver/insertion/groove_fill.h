#pragma once
// How well the tissue fills the needle's groove: the paper's second design criterion (tissue separated
// below the groove face rebounds into the groove and touches its floor: a long biopsy sample).
//
// Everything is measured in the needle's reference (CAD) frame: the particles are pulled back by the
// displacement of the nearest needle surface node (NeedleTissueContact::pull_back), so a deflected or
// bent needle is measured against its own groove. Only the part of the groove inside the tissue block
// counts. The groove is cut into slices along x; a particle covers the slices within half its spacing
// of its centre. In each slice:
//   - the tissue's bottom is the lowest lower edge (y - h/2) of a particle inside the groove's section
//     (y above the floor minus h/2, below the rod's top, |z| within the groove's half width there);
//   - fill = (y_top - bottom) / (y_top - y_floor), clamped to [0, 1], y_top the rod radius: 1 when
//     tissue reaches down to the floor, 0 when no tissue enters the groove;
//   - the floor is touched when a particle covering the slice is in contact with a groove_floor triangle.
// groove_fill is the mean fill over the slices; floor_contact_fraction the share of touched slices;
// mean_gap_mm the mean of (bottom - y_floor) over the slices (the full depth where no tissue enters).
#include <Eigen/Dense>
#include <vector>

#include "geometry/tip_geometry.h"

namespace needle {

struct GrooveFillInput {
  GrooveBox groove;                               // the groove in the reference frame
  double radius_mm = 0.5;                         // the rod's radius (top of the groove's opening)
  double tissue_min_x_mm = 0, tissue_max_x_mm = 0;  // the tissue block's x range, pulled back to the reference frame
  std::vector<Eigen::Vector3d> reference_points;  // per particle, pulled back (NaN: far from the needle)
  std::vector<double> spacing_mm;                 // per particle
  std::vector<std::uint8_t> touches_floor;        // per particle: in contact with a groove_floor triangle
  double slice_mm = 0.05;
};

struct GrooveFill {
  double length_in_tissue_mm = 0;  // the groove's length inside the tissue (0: the measure is empty)
  double groove_fill = 0;          // mean slice fill, 0..1
  double floor_contact_fraction = 0;
  double mean_gap_mm = 0;
  int particles_in_groove = 0;
};

GrooveFill measure_groove_fill(const GrooveFillInput& input);

// Whether a particle of spacing h at X (reference frame) lies in the groove's cross-section: above the floor less half
// a particle, below the rod's top (radius R), within the section's half width at that height. The x range is the
// caller's.
bool in_groove_section(const GrooveBox& groove, double radius_mm, const Eigen::Vector3d& X, double h);

}  // namespace needle
