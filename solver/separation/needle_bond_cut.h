#pragma once
// The needle cuts the tissue: a bond whose segment between its two particles passes through the needle's
// body is broken, so the two particles leave each other's supports.
//
// This is the visibility criterion of meshfree methods (Belytschko et al. 1996): particles do not interact
// through a body that separates them. An SPG support (1.8 spacings) is wider than the gap the needle opens
// (2.5 spacings wide at the paper's 0.4 mm particles), so without it the tissue above and below the needle
// stays bonded through the steel: the tissue is pushed aside and closes around the needle like a stretched
// band instead of being cut at the tip (docs/notebook/paper_studies.md measures both).
//
// A segment passes through the needle when it meets the needle's current surface at two distinct points
// (it enters and leaves). A particle that has sunk inside the needle, and so meets the surface once,
// keeps its bonds: the contact pushes it out. For a half model the surface is closed by its mirror image,
// so a bond lying in the symmetry plane is tested against the seam where the two halves meet.
#include <Eigen/Dense>
#include <cstdint>
#include <vector>

#include "solver/tissue/bond_network.h"
#include "solver/contact/contact_surface.h"
#include "solver/separation/separation_model.h"
#include "solver/tissue/spg_tissue.h"

namespace needle {

class NeedleBondCut : public SeparationModel {
 public:
  explicit NeedleBondCut(const ContactSurface& surface);

  // SeparationModel "needle_cut": cuts the bonds through the needle's body; its summary gives the bonds
  // cut (bonds_cut_by_needle) and the wall time spent finding them (bond_cut_s), its history column the bonds cut.
  std::string name() const override { return "needle_cut"; }
  void apply(SpgTissue& tissue, const NeedleModel& needle) override;
  void add_summary(nlohmann::json& summary, const SpgTissue& tissue) const override;
  std::vector<std::string> history_columns() const override { return {"bonds_cut_by_needle"}; }
  std::vector<std::string> history_values() const override { return {std::to_string(cut_)}; }
  std::int64_t bonds_cut() const { return cut_; }

  // The intact bonds whose segment at the particles' positions x passes through the needle at its
  // nodes' positions needle_x (rows: all FE nodes), in increasing order.
  std::vector<std::int64_t> bonds_through_needle(const BondNetwork& bonds, const std::vector<Vec3d>& x,
                                                 const Eigen::MatrixX3d& needle_x) const;

  // The distinct parameters s in [0, 1] where the segment a + s (b - a) meets the needle's surface
  // (for tests and diagnostics).
  std::vector<double> surface_crossings(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::MatrixX3d& needle_x) const;

 private:
  struct Grid;
  Grid build_grid(const Eigen::MatrixX3d& needle_x) const;
  // Calls visit(s) for each hit of the segment a-b with a triangle, in no particular order, until visit returns false.
  template <class Visit>
  void for_each_hit(const Grid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Visit& visit) const;
  std::vector<double> crossings(const Grid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;
  // Whether crossings() would find at least two distinct points, without collecting them.
  bool passes_through(const Grid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;

  const ContactSurface& surface_;
  std::int64_t cut_ = 0;
  double wall_s_ = 0;
};

}  // namespace needle
