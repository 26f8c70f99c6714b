#pragma once
// The tissue's minimum principal strain where the paper's LS-DYNA model shows it (its Fig. 7): on the tip's top
// facets, below the tip point, and in the groove. The paper reads these off contour plots ("about -1.2 at the top of
// SB's tip", "about -0.45 at the bottom of LMB's tip", "about -0.6 in the groove"); they are a model's outputs, used
// to diagnose ours, not measurements.
//
// The strain is the smallest principal value of the elastic Hencky strain, 1/2 ln(b_e): the total log strain
// wherever the gel has not yielded (at the calibrated E the card's yield strain is far beyond the strains of the
// run; the plastic strain is written beside it in the frames). Negative: compression.
//
// The regions, in the needle's reference (CAD) frame (particles pulled back as for the groove fill, groove_fill.h):
//   - tip_top:   particles in contact with a top or lancet facet (the tissue the bevel presses up);
//   - below_tip: particles in contact with any other surface (bottom and side bevels, the rod's underside) within
//                `tip_window_mm` behind tip point A, no higher than A (the tissue the tip presses down);
//   - groove:    particles inside the groove's section over its length in the tissue (the groove fill's region).
// Each region reports its particle count, the median and the 5th percentile of the strain (the most compressed,
// robust to one particle) and its minimum; an empty region reports a count of 0 and NaN.
#include <Eigen/Dense>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "geometry/tip_geometry.h"

namespace needle {

struct StrainProbeInput {
  std::vector<Eigen::Vector3d> reference_points;  // per particle, pulled back (NaN: far from the needle)
  std::vector<double> spacing_mm;                 // per particle
  std::vector<double> min_principal_strain;       // per particle
  std::vector<int> contact_tag;                   // per particle: the surface tag it touches, -1: none
  std::vector<std::string> tag_names;             // the surface's tags (facet names of shared/SPEC.md)
  Eigen::Vector3d tip_point = Eigen::Vector3d::Zero();  // A, in the reference frame
  std::optional<GrooveBox> groove;
  double radius_mm = 0.5;
  double tissue_min_x_mm = 0, tissue_max_x_mm = 0;  // the tissue block's x range, pulled back
  double tip_window_mm = 2.0;                       // how far behind A "below the tip" reaches (SB's bevel heel: 2.3 mm)
};

struct StrainRegion {
  int particles = 0;
  double median = 0, p05 = 0, min = 0;  // NaN when empty
};

struct StrainProbes {
  StrainRegion tip_top, below_tip, groove;
};

StrainProbes probe_strains(const StrainProbeInput& input);

// 1/2 ln of the smallest eigenvalue of a symmetric positive definite b (the smallest principal Hencky strain).
double min_principal_log_strain(const Eigen::Matrix3d& b);

}  // namespace needle
