#pragma once
// The cutting resistance (off by default): separating the tissue at the tip costs work (its fracture
// energy), which the contact's penalty never asks for: the needle's cut (separation/needle_bond_cut.h) breaks
// bonds for free. A load on the needle of its own, beside the contact (the coupled step sums them):
// every triangle of a tip facet (the surface tags in CuttingOptions::facets: the tip's ground facets, which
// the caller takes from the tip geometry) whose centroid lies in the tissue block (the box of the particles
// at the start, grown by half a spacing) and that advances into it (outward normal n, n . v > 0) is loaded
// with -p_c A n, a third on each corner. (The block, not the particles in contact: particles coarser than the
// facet's triangles touch only some of them.) It does the work p_c A n . v per unit time, booked as
// dissipation. Per millimetre of advance the needle then pays p_c times the tip's frontal area in contact:
// a fracture energy G_c = p_c A_frontal / w for a cut of width w. The reaction goes to the crack front, which
// the particles do not resolve; it is left out of the tissue (its momentum is the needle's drive's). The
// facets' normals set how the resistance bends the needle, as the paper's tip forces do.
#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "solver/contact/contact_surface.h"
#include "solver/contact/needle_tissue_contact.h"
#include "solver/needle/needle_model.h"
#include "solver/tissue/spg_tissue.h"

namespace needle {

struct CuttingOptions {
  double pressure_MPa = 0.0;         // p_c; 0: cutting costs nothing, the paper's model and the default
  std::vector<std::string> facets;   // the surface tags it loads: the tip's ground facets (not a scene key)
  bool enabled() const { return pressure_MPa > 0; }
  void validate(const std::string& where = "cutting") const;  // InputError naming the bad field
  // The cost of cutting in a run's one-line description (the paper report); empty when off, the default.
  std::string describe() const;
};

class CuttingResistance : public NeedleLoads {
 public:
  // InputError when the surface has none of the facets' tags.
  CuttingResistance(const ContactSurface& surface, const TissueParticles& particles, const CuttingOptions& options);

  void needle_forces(const Eigen::MatrixX3d& x_mm, const Eigen::MatrixX3d& v_mm_per_ms, double time_ms, NodalForces& force_N) override;

  // Its work since the start (mJ; dissipated), and at the last evaluation its magnitude (sum of p_c A) and
  // its force per facet tag (indexed like ContactSurface::tag_names()).
  double work_mJ() const { return work_mJ_; }
  double force_N() const { return force_N_; }
  const std::vector<FacetContact>& facets() const { return facets_; }
  Eigen::Vector3d force_on_needle_N() const { return force_on_needle_N_; }
  // Adds its forces at the last evaluation to a contact report (facets, total, cutting force).
  void add_to(ContactReport& report) const;
  // Its summary entry "cutting": the pressure, its work, its force at the end.
  void add_summary(nlohmann::json& summary) const;

 private:
  const ContactSurface& surface_;
  CuttingOptions options_;
  std::vector<int> triangles_;          // the tip facets' triangles
  std::vector<double> orientation_;     // +1 or -1 per triangle of the surface: turns its winding's normal outward (forward)
  Eigen::AlignedBox3d block_;           // the tissue block the tip cuts (particles at the start, grown by half a spacing)
  std::vector<FacetContact> facets_;
  Eigen::Vector3d force_on_needle_N_ = Eigen::Vector3d::Zero();
  double force_N_ = 0, last_power_mW_ = 0, work_mJ_ = 0, last_eval_ms_ = 0;
};

}  // namespace needle
