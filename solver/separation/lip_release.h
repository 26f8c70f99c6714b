#pragma once
// The lip below the tip point, crushed (the default) or cut loose: the tissue a ground tip meets below its tip
// point A, inside the rod's outline, loses its shear stiffness (crushed) or every bond (free).
//
// Why (docs/notebook/lip_release.md): a multi-bevel tip cuts the tissue at A, and the rod's body below A must
// then move a lip of tissue as thick as A's height above the rod's bottom (SB 0, LMB 0.21, AMB 0.43,
// HMB 0.80 mm). Bonded and elastic, that lip is pressed down and presses the tissue below it under the whole
// shaft, which pushes the needle up: calibrated on SB, LMB, AMB and HMB then ended 0.28, 1.26 and 1.07 mm above
// the experiment, and the global study found no admissible setting that gave the measured LMB -> AMB plateau.
// A lip squeezed between a blade's facets and the rod is crushed: the gel there is torn through its thickness
// and flows round the rod, pushing only by its pressure.
//
// Modes (a scene's default is crushed, runs/scene.h; SeparationOptions{} leaves the lip off):
// - crushed: the band's bonds stay, but its material keeps only its pressure (kParticleCrushed
//   in SpgTissue: no shear stress, no elastic shear strain stored). It keeps the lip's volume.
// - free: every bond of the band is cut: free mass points that the needle's contact still pushes but that carry
//   no stress (the limit where the lip carries nothing; it over-relieves, docs/notebook/lip_release.md).
// - off: the lip stays as the tissue is (a scene's model before 2026-11-27).
//
// Which particles: x within kWindowBehindMm behind A (the tip has passed them),
// A.y - below_mm - depth_mm <= y < A.y - below_mm, and inside the rod's outline,
// (y - axis_y)^2 + (z - axis_z)^2 <= r^2, where the rod's axis is y = z = 0 in the needle's frame, moved with
// A's displacement, and r is the needle's largest distance from that axis. depth_mm is unbounded by default (the
// whole lip, down to the rod's bottom) and below_mm 0: the two shape a band for studies (a lip's top, or its part
// deeper than a length). Once released, a particle stays released. A tip point on the rod's bottom (SB) has no lip:
// make_separation_models adds no model for it, and its runs are the same bit for bit whatever the mode. "Below" is the
// needle frame's -y, the side opposite the groove and the top bevel (shared/SPEC.md's axes): a needle turned upside
// down in its own frame is a different needle to this model.
#include <Eigen/Dense>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "solver/separation/separation_model.h"
#include "solver/tissue/bond_network.h"
#include "solver/tissue/spg_tissue.h"

namespace needle {

enum class LipReleaseMode { off, free, crushed };
const char* lip_release_mode_name(LipReleaseMode mode);
LipReleaseMode lip_release_mode_from_name(const std::string& name);  // InputError for another name

struct LipReleaseOptions {
  LipReleaseMode mode = LipReleaseMode::off;
  double below_mm = 0.0;                                         // the band's top lies this far below A (>= 0)
  double depth_mm = std::numeric_limits<double>::infinity();  // the band's depth (> 0); unbounded: the whole lip
  bool enabled() const { return mode != LipReleaseMode::off; }
  bool whole_lip() const { return below_mm == 0 && depth_mm == std::numeric_limits<double>::infinity(); }
  void validate(const std::string& where = "lip_release") const;  // InputError naming the bad field
  // The lip in a run's one-line description (the paper report); empty when it is `unnamed` (a scene's default).
  std::string describe(const LipReleaseOptions& unnamed) const;
};

constexpr double kNoLipMm = 1e-6;  // a lip thinner than this is none (a tip point on the rod's bottom)
constexpr const char* kWholeLipText = "whole lip";  // an unbounded depth, as scene files and summaries write it

class LipRelease : public SeparationModel {
 public:
  static constexpr double kWindowBehindMm = 0.5;  // a particle is released up to this far behind A

  // needle_reference_mm: the needle's nodes in its own (CAD) frame, rod axis y = z = 0; the tip point is its
  // most distal node.
  LipRelease(const Eigen::MatrixX3d& needle_reference_mm, const LipReleaseOptions& options);

  // The particles (not yet released) that lie in the released band, with the needle's nodes at needle_x.
  std::vector<std::int32_t> particles_in_band(const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x) const;
  // The intact bonds with at least one particle in `particles`, in increasing order.
  static std::vector<std::int64_t> bonds_of(const BondNetwork& bonds, const std::vector<std::int32_t>& particles);
  // Releases the band's particles now (free: cuts their bonds; crushed: flags them); returns how many it released.
  std::int64_t release(SpgTissue& tissue, const Eigen::MatrixX3d& needle_x);

  double rod_radius_mm() const { return rod_radius_mm_; }
  // The lip's thickness in the needle's frame: A's height above the rod's bottom (0 for a tip on the bottom).
  double lip_thickness_mm() const { return tip_reference_mm_.y() + rod_radius_mm_; }
  // The same for a needle's nodes in its own frame (its most distal node the tip point).
  static double lip_thickness_mm(const Eigen::MatrixX3d& needle_reference_mm);
  const LipReleaseOptions& options() const { return options_; }
  std::int64_t particles_released() const { return released_count_; }
  std::int64_t bonds_cut() const { return cut_; }

  // SeparationModel "lip_release": its summary entry "lip_release" gives the depth, the lip's thickness,
  // the particles released, the bonds cut and the wall time; its history column the particles released.
  std::string name() const override { return "lip_release"; }
  void apply(SpgTissue& tissue, const NeedleModel& needle) override;
  void add_summary(nlohmann::json& summary, const SpgTissue& tissue) const override;
  std::vector<std::string> history_columns() const override { return {"lip_particles_released"}; }
  std::vector<std::string> history_values() const override;

 private:
  LipReleaseOptions options_;
  Eigen::Index tip_node_ = 0;
  Eigen::Vector3d tip_reference_mm_ = Eigen::Vector3d::Zero();
  double rod_radius_mm_ = 0;
  std::vector<std::uint8_t> released_;  // one per particle, sized at the first call
  std::int64_t released_count_ = 0, cut_ = 0;
  double wall_s_ = 0;
};

}  // namespace needle
