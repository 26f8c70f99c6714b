#pragma once
// Linear statics and vibration of the needle with some nodes clamped: K u = f by a sparse Cholesky
// factorisation (CHOLMOD through Eigen), and the lowest modes of K phi = omega^2 M phi (lumped M) by
// Lanczos iteration (Spectra) on the operator M^1/2 K^-1 M^1/2, which reuses the same factorisation.
#include <Eigen/Dense>
#include <memory>
#include <vector>

#include "solver/needle/fe_needle.h"

namespace needle {

struct VibrationMode {
  double frequency_hz = 0;
  Eigen::MatrixX3d shape;  // #nodes x 3, unit mass-norm
};

class ClampedNeedle {
 public:
  // InputError if no node is clamped (the needle could move rigidly) or a node index is out of range.
  ClampedNeedle(const FeNeedle& needle, const std::vector<int>& clamped_nodes);
  ~ClampedNeedle();
  ClampedNeedle(const ClampedNeedle&) = delete;
  ClampedNeedle& operator=(const ClampedNeedle&) = delete;

  // Displacements (#nodes x 3, mm) under nodal loads (#nodes x 3, N); clamped nodes stay at zero.
  Eigen::MatrixX3d solve(const Eigen::MatrixX3d& load_N) const;
  // The `count` lowest modes, lowest first.
  std::vector<VibrationMode> lowest_modes(int count) const;
  int free_dofs() const { return static_cast<int>(free_dof_.size()); }

 private:
  Eigen::VectorXd reduce(const Eigen::MatrixX3d& field) const;
  Eigen::MatrixX3d expand(const Eigen::VectorXd& reduced) const;

  const FeNeedle& needle_;
  std::vector<int> free_dof_;  // reduced index -> global dof
  struct Factor;
  std::unique_ptr<Factor> factor_;
};

}  // namespace needle
