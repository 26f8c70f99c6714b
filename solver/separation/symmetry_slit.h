#pragma once
// A crack in the needle's plane of symmetry: behind the tip point the tissue opens as a slit in the
// plane z = 0, so the needle's body can push the tissue aside (+-z) instead of only up and down.
//
// The needle's cut (needle_bond_cut.h) separates the tissue along the needle's own surface: in the
// symmetry plane that surface's normals lie in the plane, so every particle on the plane that the tip
// reaches is pushed up or down, and the tissue below a tip point above the rod's bottom stays pressed
// down under the whole shaft (docs/notebook/paper_studies.md). A real tip's cutting edges can instead split the gel
// in the plane, as a knife does. In a half model that split is the symmetry particles leaving the
// plane: their mirror images move the other way, and the plane is where the two faces meet, so an
// opened particle keeps only z >= 0 (kParticleOpenSymmetry, explicit_dynamics.h).
//
// Which particles open: those on the plane that lie behind the tip point plus lead_mm, within
// half_height_mm of the rod's axis (y = 0 in the needle's frame, moved with the tip's y displacement).
// Once open, a particle stays open. half_height_mm = 0 turns the slit off; the rod's radius (0.5 mm) is
// a slit as tall as the rod.
#include <Eigen/Dense>
#include <cstdint>
#include <string>
#include <vector>

#include "solver/separation/separation_model.h"
#include "solver/tissue/spg_tissue.h"

namespace needle {

struct SymmetrySlitOptions {
  double half_height_mm = 0.0;  // 0: no slit
  double lead_mm = 0.0;         // the slit's front runs this far ahead of the tip point (>= 0)
  bool enabled() const { return half_height_mm > 0; }
  void validate(const std::string& where = "slit") const;  // InputError naming the bad field
  // The slit in a run's one-line description (the paper report); empty when off, the default.
  std::string describe() const;
};

class SymmetrySlit : public SeparationModel {
 public:
  // needle_reference_mm: the needle's nodes in its own (CAD) frame; the tip point is its most distal node.
  SymmetrySlit(const Eigen::MatrixX3d& needle_reference_mm, const SymmetrySlitOptions& options);

  // Opens the symmetry particles the slit now reaches, with the needle's nodes at needle_x; returns
  // how many it opened now.
  std::int64_t open(TissueParticles& particles, const Eigen::MatrixX3d& needle_x);
  std::int64_t opened() const { return opened_; }
  // How far the slit stands open: the largest and the mean z of the opened particles that are still
  // integration points (a detached crack-face particle flies free and says nothing of the slit); 0 if none.
  struct Opening {
    double max_mm = 0, mean_mm = 0;
  };
  static Opening opening(const SpgTissue& tissue);
  const SymmetrySlitOptions& options() const { return options_; }

  // SeparationModel "slit": opens the particles the slit reaches; its summary entry "slit" gives the
  // particles opened and the opening's largest and mean height.
  std::string name() const override { return "slit"; }
  void apply(SpgTissue& tissue, const NeedleModel& needle) override { open(tissue.particles(), needle.positions_mm()); }
  void add_summary(nlohmann::json& summary, const SpgTissue& tissue) const override;

 private:
  SymmetrySlitOptions options_;
  Eigen::Index tip_node_ = 0;
  Eigen::Vector3d tip_reference_mm_ = Eigen::Vector3d::Zero();
  std::int64_t opened_ = 0;
  bool candidates_listed_ = false;
  std::vector<std::int32_t> closed_;  // the symmetry particles not opened yet (listed at the first open())
};

}  // namespace needle
