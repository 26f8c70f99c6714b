#pragma once
// The biopsy sample (issue 50): the tissue the fired cannula encloses in the groove when it stops.
//
// Measured in the needle's reference frame (solver/needle/needle_axis_frame.h), where the cannula is a straight tube
// around the x axis. A particle is captured when its centre lies inside the tube's mid-wall cylinder (the surface
// its edge cut along, cannula_firing.h), between x_lo and x_hi (the groove's walls, within the cannula's stroke), and
// above the groove's floor less half its spacing (so the tissue in the clearance beside the rod below the floor is
// not counted; without a groove, every particle in the bore counts). A particle stands for the tissue within half its
// spacing of its centre along x.
//   length_mm:       the extent along the axis of all captured tissue (its front edge less its back edge);
//   floor_layer_length_mm, floor_layer_covered_mm: for the captured particles of the floor's nearest layer, by
//                    geometry (the centre within the contact's skin and a quarter of its spacing of the floor: the
//                    contact holds a resting particle at the skin; the next layer lies a spacing higher), their extent
//                    along the axis and the length of the axis under them (gaps left out);
//   I_s_mm:          the sample length compared with the paper's: floor_layer_covered_mm, the length of groove floor
//                    the captured tissue rests on. Not the layer's extent: by geometry that is the whole groove in every
//                    paper needle (docs/notebook/sampling.md), so it cannot tell them apart;
//   floor_length_mm, floor_covered_mm: the same two as the layer's for the particles the contact lists as touching the
//                    floor (a contact with a groove_floor triangle; the caller says when). The kinematic contact lists a
//                    particle only in a step it pushes it back, so a sample resting on the floor is counted by a few of
//                    its particles at a time: kept beside I_s, not compared (the first reading of I_s was this
//                    extent; it rests on 4 particles for HMB and moved by 16 mm between lattices);
//   volume_mm3, mass_g: the captured particles' reference volume and (physical) mass.
#include <Eigen/Dense>
#include <cstdint>
#include <optional>
#include <vector>

namespace needle {

struct TissueSampleInput {
  std::vector<Eigen::Vector3d> reference_points;  // per particle, in the needle's reference frame
  std::vector<double> spacing_mm, volume_mm3, mass_g;
  std::vector<std::uint8_t> touches_floor;        // per particle (empty: none does)
  double bore_radius_mm = 0.61;                   // the cylinder the edge cut along
  double x_lo_mm = 0, x_hi_mm = 0;
  std::optional<double> floor_y_mm;               // the groove's floor (none: no groove)
  double contact_skin_mm = 0.02;                  // the floor's nearest layer: centres within skin + h/4 of it
};

struct TissueSample {
  std::int64_t particles = 0, floor_particles = 0;
  double length_mm = 0, floor_length_mm = 0, floor_covered_mm = 0, volume_mm3 = 0, mass_g = 0;
  double floor_layer_length_mm = 0, floor_layer_covered_mm = 0;
  double I_s_mm() const { return floor_layer_covered_mm; }  // the length compared with the paper's
  std::int64_t floor_layer_particles = 0;
  double back_x_mm = 0, front_x_mm = 0;  // the captured tissue's extent (reference frame; 0 when empty)
  std::vector<std::uint8_t> captured;    // per particle
  std::vector<std::uint8_t> in_floor_layer;  // per particle: captured, and in the floor's nearest layer (I_s covers these)
};

// The name of I_s's measure, written beside it in a run's summary (summary.json sample.I_s_measure).
inline constexpr const char* kSampleLengthMeasure = "floor_layer_covered_mm";

TissueSample measure_tissue_sample(const TissueSampleInput& input);

}  // namespace needle
