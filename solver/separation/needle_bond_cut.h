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
//
// Each step's search skips at once the bonds whose two particles lie on one side of the needle's box; most of the
// block's bonds are so, but reading all of them every step streamed the whole pair list (19 MB at the paper's
// block) 2 000 times a run. So the step scans a list of candidates instead: the intact bonds not wholly on one side
// of the box widened by a margin, made again once the box has grown by half the margin or a particle has moved half
// the margin since. A bond left off the list then still lies wholly on one side of the current box, so the same
// bonds are cut, in the same order, as a scan of every intact bond (tests/solver/test_needle_bond_cut.cpp). The grid
// holds only the triangles that reach into the particles' box (a bond's segment lies in it): early in a run most of the
// needle is still in the cannula, and the grid of the whole needle was a quarter of the cut's time.
//
// Most candidates lie beside the needle without touching it, and were walked through the grid every step only to find
// no triangle's box overlapping theirs (seven walks in eight on SB). So a candidate that does not pass through keeps a
// certificate: on each axis k, a gap g_k such that every triangle's box (the needle's, within reach of the clip box)
// lies apart from the bond's box on some axis k by at least g_k. A box moves by at most what its corners move, so while
// on every axis the bond's particles have moved less than g_k minus the needle's nodes' motion since (a bound summed
// step by step), every box still lies apart and the bond still cannot pass through: its test is skipped. The same
// bonds are cut, in the same order, as without the certificates (the test drives the needle and the particles both
// ways, and a needle that jumps). The needle moves mostly along its axis and the tissue beside it barely at all, so
// the gaps are found on a box widened along each axis by what the needle has been moving there, over a few steps.
// The bonds lying along the needle's side overlap its facets' boxes; one wholly on one side of such a facet's plane is
// apart from it while the motion along the facet's normal stays below its distance to the plane, and the gaps are
// lowered until their motion along that normal does.
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
  // The candidates' margin; 0 scans every intact bond every step (the reference the list is tested against).
  static constexpr double kCandidateMarginMm = 0.4;
  // certify: skip the tests of the bonds whose certificate holds (needs a positive margin).
  explicit NeedleBondCut(const ContactSurface& surface, double candidate_margin_mm = kCandidateMarginMm, bool certify = true);

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
  // The same bonds, in the same order, from the candidate list kept between calls (made again when it may miss one).
  // The calls must follow one tissue: the same bonds, broken only ever more, and the same particles.
  std::vector<std::int64_t> bonds_through_needle_tracked(const BondNetwork& bonds, const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x);
  // How often the candidate list was made, and its length the last time (for the run's summary and the tests).
  std::int64_t candidate_lists_made() const { return lists_made_; }
  size_t candidates() const { return candidates_.size(); }
  // The candidates' tests made (a walk through the grid) and skipped on their certificate, over all calls.
  std::int64_t tests_made() const { return tests_made_; }
  std::int64_t tests_skipped() const { return tests_skipped_; }
  const ContactSurface& surface() const { return surface_; }

  // The distinct parameters s in [0, 1] where the segment a + s (b - a) meets the needle's surface
  // (for tests and diagnostics).
  std::vector<double> surface_crossings(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::MatrixX3d& needle_x) const;

  // The searches' grid of the needle's current triangles (solver/separation/needle_cut_grid.h).
  struct Grid;

 private:
  // How far beyond the particles' box the grid holds triangles when certificates are kept: no gap exceeds it.
  static constexpr double kCertificateReachMm = 0.1;
  // The grid of the needle's triangles that reach into [clip_lo, clip_hi] (the segments tested lie there).
  Grid build_grid(const Eigen::MatrixX3d& needle_x, const Eigen::Vector3d& clip_lo, const Eigen::Vector3d& clip_hi) const;
  // Calls visit(s) for each hit of the segment a-b with a triangle, in no particular order, until visit returns false;
  // overlapped, when given, is set when a triangle's box overlaps the segment's.
  template <class Visit>
  void for_each_hit(const Grid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Visit& visit, bool* overlapped = nullptr) const;
  std::vector<double> crossings(const Grid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;
  // Whether crossings() would find at least two distinct points, without collecting them.
  bool passes_through(const Grid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;
  bool passes_through(const Grid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b, bool& overlapped) const;

  // As passes_through, and when the segment does not pass through, the gaps of its certificate (all zero when none:
  // a triangle's box overlaps the segment's and the segment crosses or touches its plane). Looks at the triangles within
  // dilation of the segment's box along each axis, and prefers the gaps that last the most steps at the needle's rate
  // of motion along each axis.
  bool passes_through_or_certify(const Grid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& dilation,
                                 const Eigen::Vector3d& rate, Eigen::Vector3d& gap) const;

  // The intact pairs of list (in its order) not wholly on one side of [lo, hi], whose ends pass_through: the bonds.
  std::vector<std::int64_t> scan(const Grid& grid, const IntactPair* pairs, std::int64_t count, const BondNetwork& bonds,
                                 const std::vector<Vec3d>& x) const;
  // The same over the candidates, skipping those whose certificate holds and certifying those tested anew.
  std::vector<std::int64_t> scan_certified(const Grid& grid, const BondNetwork& bonds, const std::vector<Vec3d>& x);
  // The needle's motion since the last call, added to the bound; the certificates are dropped when the half model's
  // mirrored triangles change.
  void track_needle_motion(const Eigen::MatrixX3d& needle_x, std::uint64_t mirrored_signature);

  // A candidate's certificate: its particles' positions when it was last tested, the gaps then (0: none; -1: none, a
  // triangle's box overlapped its own, so the plain walk is tried first) and the needle's motion bound then (an index
  // into needle_motion_).
  struct Certificate {
    double a[3] = {0, 0, 0}, b[3] = {0, 0, 0}, gap[3] = {0, 0, 0};
    std::int32_t motion_index = 0;
  };

  const ContactSurface& surface_;
  double margin_mm_;
  std::vector<IntactPair> candidates_;      // the intact pairs not wholly on one side of [list_lo_, list_hi_] when listed
  std::vector<Vec3d> listed_x_;             // the particles' positions then
  Eigen::Vector3d list_lo_ = Eigen::Vector3d::Zero(), list_hi_ = Eigen::Vector3d::Zero();  // the box then, widened by the margin
  bool listed_ = false;
  bool certify_ = true;
  std::vector<Certificate> certificates_;   // parallel to candidates_
  std::vector<Eigen::Vector3d> needle_motion_;  // per call: the summed bound on any node's motion along each axis
  Eigen::MatrixX3d last_needle_x_;
  std::uint64_t mirrored_signature_ = 0;
  std::int64_t tests_made_ = 0, tests_skipped_ = 0;
  std::int64_t lists_made_ = 0;
  std::int64_t cut_ = 0;
  double wall_s_ = 0;
};

}  // namespace needle
