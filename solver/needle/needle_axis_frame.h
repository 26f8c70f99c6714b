#pragma once
// The needle's reference (CAD) frame found from its axis: a point of the world is carried back by the displacement of
// the needle's cross-section it lies beside, so that a tube around the deflected needle (the firing cannula,
// solver/insertion/cannula_firing.h) is a straight tube around the x axis in this frame.
//
// The needle's nodes are grouped in slabs of their reference x; a slab's displacement is the mean of its nodes'. A
// point p maps to X = p - u(s), s its slab's reference x, found from s = p.x - u_x(s) (two fixed-point passes from
// the mean axial displacement: u_x varies by a few micrometres along the needle); u is linear between slab centres
// and constant past the ends. The cross-section's rotation is left out: at a slope of 0.05 it moves a point 0.6 mm
// from the axis by 0.03 mm along x. Without a needle (no nodes) the frame is the world's.
#include <Eigen/Dense>
#include <vector>

#include "solver/tissue/spg_tissue.h"

namespace needle {

class NeedleAxisFrame {
 public:
  static constexpr double kSlabMm = 0.5;
  NeedleAxisFrame() = default;  // the world's frame
  // reference_mm: the needle's nodes in its reference frame.
  explicit NeedleAxisFrame(const Eigen::MatrixX3d& reference_mm, double slab_mm = kSlabMm);

  // The slabs' displacements with the needle's nodes at x_mm (same rows as the reference).
  void update(const Eigen::MatrixX3d& x_mm);
  // A world point carried back into the reference frame.
  Eigen::Vector3d to_reference(const Vec3d& p) const;
  // The axis's displacement at reference x (zero for the world's frame).
  Eigen::Vector3d displacement_at(double reference_x_mm) const;
  bool is_world() const { return slab_count_ == 0; }

 private:
  Eigen::MatrixX3d reference_;
  std::vector<int> slab_of_node_;
  std::vector<int> nodes_in_slab_;
  std::vector<Eigen::Vector3d> slab_displacement_;
  double min_x_mm_ = 0, slab_mm_ = kSlabMm, mean_axial_mm_ = 0;
  int slab_count_ = 0;
};

}  // namespace needle
