#pragma once
// A crack the tip drives ahead of the needle's outline: planar fins from the tip point A, each a half-plane
// along the insertion axis that leaves A in a direction of the cross-section, cut the tissue's bonds
// that cross them as the tip passes.
//
// The needle's cut (needle_bond_cut.h) separates the tissue only where the needle's body is, so the gel
// splits along the rod's own surface. A real tip separates it at A (the paper's "tissue separation
// point") and the crack can run past the rod's outline: a gel cut by a blade-like edge splits in the
// plane of the edge. How far the crack runs beyond the rod is not known; the fins make it a parameter.
//
// A fin leaves A in the cross-section's direction u = (0, sin psi, cos psi): psi = 0 runs toward +z
// (horizontal, at A's height: the tissue above A and below it separate beyond the rod), psi = 90 up,
// psi = -90 down. A bond is cut when its segment crosses a fin's half-plane at a point whose distance
// from A along u is at most reach_mm and whose x lies between kWindowBehindMm behind A and lead_mm
// ahead of it. The fins follow A's current position, so the crack is laid down where the tip passes;
// behind the window it stays as it was made (bonds do not heal). A bond crosses a fin only when its two
// particles lie strictly on either side of the fin's plane. In a half model (z >= 0) a fin with cos psi < 0
// lies in the mirror half and cuts nothing (its mirror image is the fin at 180 - psi), and a fin at +-90 lies
// in the symmetry plane and cuts nothing either: that split is the slit's (symmetry_slit.h).
#include <Eigen/Dense>
#include <cstdint>
#include <string>
#include <vector>

#include "solver/tissue/bond_network.h"
#include "solver/separation/separation_model.h"
#include "solver/tissue/spg_tissue.h"

namespace needle {

struct TipCrackOptions {
  double reach_mm = 0.0;               // 0: no crack; measured from A in the fin's direction (the rod's radius is 0.5)
  std::vector<double> angles_deg{0.0};  // the fins' directions psi in the cross-section (0: +z, horizontal)
  double lead_mm = 0.0;                // the crack's front runs this far ahead of A (>= 0)
  bool enabled() const { return reach_mm > 0; }
  void validate(const std::string& where = "crack") const;  // InputError naming the bad field
  // The crack in a run's one-line description (the paper report); empty when off, the default.
  std::string describe() const;
};

class TipCrack : public SeparationModel {
 public:
  static constexpr double kWindowBehindMm = 0.5;  // a fin cuts bonds crossing it up to this far behind A

  // needle_reference_mm: the needle's nodes in its own (CAD) frame; the tip point is its most distal node.
  TipCrack(const Eigen::MatrixX3d& needle_reference_mm, const TipCrackOptions& options);

  // The intact bonds whose segment at the particles' positions x crosses a fin, with the needle's
  // nodes at needle_x, in increasing order (empty when the crack is off).
  std::vector<std::int64_t> bonds_across(const BondNetwork& bonds, const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x) const;
  const TipCrackOptions& options() const { return options_; }

  // SeparationModel "crack": cuts the bonds across the fins; its summary entry "crack" gives the reach,
  // the bonds cut and the wall time spent finding them.
  std::string name() const override { return "crack"; }
  void apply(SpgTissue& tissue, const NeedleModel& needle) override;
  void add_summary(nlohmann::json& summary, const SpgTissue& tissue) const override;
  std::int64_t bonds_cut() const { return cut_; }

 private:
  TipCrackOptions options_;
  std::int64_t cut_ = 0;
  double wall_s_ = 0;
  Eigen::Index tip_node_ = 0;
};

}  // namespace needle
