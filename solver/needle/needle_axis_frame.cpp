#include "solver/needle/needle_axis_frame.h"

#include <algorithm>
#include <cmath>

#include "core/input_error.h"

namespace needle {

NeedleAxisFrame::NeedleAxisFrame(const Eigen::MatrixX3d& reference_mm, double slab_mm) : reference_(reference_mm), slab_mm_(slab_mm) {
  NEEDLE_REQUIRE(slab_mm > 0, "needle axis frame: the slab must be positive");
  if (reference_mm.rows() == 0) return;
  min_x_mm_ = reference_mm.col(0).minCoeff();
  slab_count_ = std::max(1, static_cast<int>(std::ceil((reference_mm.col(0).maxCoeff() - min_x_mm_) / slab_mm)) + 1);
  nodes_in_slab_.assign(static_cast<size_t>(slab_count_), 0);
  slab_of_node_.resize(static_cast<size_t>(reference_mm.rows()));
  for (Eigen::Index n = 0; n < reference_mm.rows(); ++n) {
    const int s = std::clamp(static_cast<int>(std::floor((reference_mm(n, 0) - min_x_mm_) / slab_mm)), 0, slab_count_ - 1);
    slab_of_node_[static_cast<size_t>(n)] = s;
    ++nodes_in_slab_[static_cast<size_t>(s)];
  }
  slab_displacement_.assign(static_cast<size_t>(slab_count_), Eigen::Vector3d::Zero());
}

void NeedleAxisFrame::update(const Eigen::MatrixX3d& x_mm) {
  if (is_world()) return;
  NEEDLE_REQUIRE(x_mm.rows() == reference_.rows(), "needle axis frame: the positions belong to another needle");
  std::vector<Eigen::Vector3d> sum(static_cast<size_t>(slab_count_), Eigen::Vector3d::Zero());
  for (Eigen::Index n = 0; n < x_mm.rows(); ++n) sum[static_cast<size_t>(slab_of_node_[static_cast<size_t>(n)])] += (x_mm.row(n) - reference_.row(n)).transpose();
  // A slab without nodes (a gap in the mesh longer than a slab) takes its nearest filled neighbour's displacement.
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  int last_filled = -1;
  for (int s = 0; s < slab_count_; ++s) {
    const size_t k = static_cast<size_t>(s);
    if (nodes_in_slab_[k] > 0) {
      slab_displacement_[k] = sum[k] / nodes_in_slab_[k];
      for (int e = last_filled + 1; e < s; ++e) slab_displacement_[static_cast<size_t>(e)] = slab_displacement_[k];
      last_filled = s;
    }
    total += sum[k];
  }
  for (int e = last_filled + 1; e < slab_count_; ++e) slab_displacement_[static_cast<size_t>(e)] = slab_displacement_[static_cast<size_t>(last_filled)];
  mean_axial_mm_ = total.x() / static_cast<double>(x_mm.rows());
}

Eigen::Vector3d NeedleAxisFrame::displacement_at(double reference_x_mm) const {
  if (is_world()) return Eigen::Vector3d::Zero();
  // Linear between slab centres, constant past the first and the last.
  const double f = (reference_x_mm - min_x_mm_) / slab_mm_ - 0.5;
  if (f <= 0) return slab_displacement_.front();
  if (f >= slab_count_ - 1) return slab_displacement_.back();
  const int s = static_cast<int>(std::floor(f));
  const double w = f - s;
  return (1 - w) * slab_displacement_[static_cast<size_t>(s)] + w * slab_displacement_[static_cast<size_t>(s + 1)];
}

Eigen::Vector3d NeedleAxisFrame::to_reference(const Vec3d& p) const {
  if (is_world()) return p;
  double s = p.x() - mean_axial_mm_;
  for (int pass = 0; pass < 2; ++pass) s = p.x() - displacement_at(s).x();
  return p - displacement_at(s);
}

}  // namespace needle
