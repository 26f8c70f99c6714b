#pragma once
// The thin lip below the tip point, released: the tissue the tip meets below A, inside the rod's outline and at
// most depth_mm below A, is cut loose from everything (all its bonds are cut), so the needle's lower facets
// push free mass points instead of pressing a layer of bonded gel into the tissue below.
//
// Why (docs/notebook/lip_release.md): a multi-bevel tip cuts the tissue at A, and the rod's body below A must
// then move a lip of tissue as thick as A's height above the rod's bottom (SB 0, LMB 0.21, AMB 0.43,
// HMB 0.80 mm). In the default model that lip stays bonded to the tissue below it and presses it down under
// the whole shaft, which pushes the needle up; the global study found no admissible setting that flattens
// the measured LMB -> AMB plateau. In the paper's LS-DYNA model a lip thinner than its 0.4 mm particles is
// one particle and carries next to nothing. This model makes that a length scale of its own: the band
// depth_mm below A is separated where the tip passes (the limit where the lip carries no load at all:
// released particles keep their mass and momentum, and the needle's contact still acts on them, but no
// stress). The band starts below_mm under A: below_mm = 0 releases the lip's top depth_mm (a lip thinner than
// depth_mm whole); below_mm = l with a deep band releases whatever part of a lip is thicker than l, the limit of
// an energy argument in which pressing a layer stores energy in proportion to its thickness while splitting it
// off costs a fracture energy per area, so a lip thicker than a length l ~ G_c / E splits (docs/notebook/lip_release.md).
//
// Which particles: x within kWindowBehindMm behind A (the tip has passed them),
// A.y - below_mm - depth_mm <= y < A.y - below_mm,
// and inside the rod's outline, (y - axis_y)^2 + (z - axis_z)^2 <= r^2, where the rod's axis is y = z = 0 in
// the needle's frame, moved with A's displacement, and r is the needle's largest distance from that axis.
// Once released, a particle stays released (its bonds do not heal).
//
// Two ways to release (mode): free (the default above: every bond cut, a free mass point) and crushed (the bonds
// stay, but the material there loses its shear stiffness and keeps only its pressure, kParticleCrushed in
// SpgTissue: crushed gel that flows round the rod but still pushes where it is squeezed). Free is the limit where
// the lip carries nothing; crushed keeps the lip's volume.
#include <Eigen/Dense>
#include <cstdint>
#include <string>
#include <vector>

#include "solver/separation/separation_model.h"
#include "solver/tissue/bond_network.h"
#include "solver/tissue/spg_tissue.h"

namespace needle {

enum class LipReleaseMode { free, crushed };
const char* lip_release_mode_name(LipReleaseMode mode);
LipReleaseMode lip_release_mode_from_name(const std::string& name);  // InputError for another name

struct LipReleaseOptions {
  double depth_mm = 0.0;  // 0: no release (the default); the band below tip point A that is cut loose
  double below_mm = 0.0;  // the band's top lies this far below A (>= 0)
  LipReleaseMode mode = LipReleaseMode::free;
  bool enabled() const { return depth_mm > 0; }
  void validate(const std::string& where = "lip_release") const;  // InputError naming the bad field
};

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
