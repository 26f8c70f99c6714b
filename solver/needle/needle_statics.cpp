#include "solver/needle/needle_statics.h"

#include <Eigen/CholmodSupport>
#include <Spectra/SymEigsSolver.h>
#include <fmt/format.h>

#include "core/input_error.h"
#include "core/solver_error.h"

namespace needle {

struct ClampedNeedle::Factor {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>> llt;
};

namespace {

// y = M^1/2 K^-1 M^1/2 x: its largest eigenvalues are 1 / omega^2 of the lowest modes.
class InverseStiffnessOperator {
 public:
  using Scalar = double;
  InverseStiffnessOperator(const Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>>& llt,
                           const Eigen::VectorXd& sqrt_mass)
      : llt_(llt), sqrt_mass_(sqrt_mass) {}
  Eigen::Index rows() const { return sqrt_mass_.size(); }
  Eigen::Index cols() const { return sqrt_mass_.size(); }
  void perform_op(const double* x_in, double* y_out) const {
    const Eigen::Map<const Eigen::VectorXd> x(x_in, rows());
    Eigen::Map<Eigen::VectorXd> y(y_out, rows());
    const Eigen::VectorXd rhs = sqrt_mass_.cwiseProduct(x);
    y = sqrt_mass_.cwiseProduct(llt_.solve(rhs));
  }

 private:
  const Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>>& llt_;
  const Eigen::VectorXd& sqrt_mass_;
};

}  // namespace

ClampedNeedle::ClampedNeedle(const FeNeedle& needle, const std::vector<int>& clamped_nodes)
    : needle_(needle), factor_(std::make_unique<Factor>()) {
  NEEDLE_REQUIRE(!clamped_nodes.empty(), "a static or modal analysis needs clamped nodes (none given)");
  std::vector<char> clamped(static_cast<size_t>(needle.num_nodes()), 0);
  for (int n : clamped_nodes) {
    NEEDLE_REQUIRE(n >= 0 && n < needle.num_nodes(), fmt::format("clamped node {} does not exist", n));
    clamped[static_cast<size_t>(n)] = 1;
  }
  std::vector<int> reduced_index(3 * static_cast<size_t>(needle.num_nodes()), -1);
  for (int n = 0; n < needle.num_nodes(); ++n)
    if (!clamped[static_cast<size_t>(n)])
      for (int k = 0; k < 3; ++k) {
        reduced_index[3 * static_cast<size_t>(n) + k] = static_cast<int>(free_dof_.size());
        free_dof_.push_back(3 * n + k);
      }
  const Eigen::SparseMatrix<double> K = needle.stiffness_matrix();
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(K.nonZeros()));
  for (int col = 0; col < K.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(K, col); it; ++it) {
      const int r = reduced_index[static_cast<size_t>(it.row())], c = reduced_index[static_cast<size_t>(it.col())];
      if (r >= 0 && c >= 0 && r >= c) triplets.emplace_back(r, c, it.value());
    }
  Eigen::SparseMatrix<double> reduced(free_dofs(), free_dofs());
  reduced.setFromTriplets(triplets.begin(), triplets.end());
  factor_->llt.compute(reduced.selfadjointView<Eigen::Lower>());
  if (factor_->llt.info() != Eigen::Success)
    throw SolverError("the clamped needle's stiffness matrix is not positive definite (is the needle held?)");
}

ClampedNeedle::~ClampedNeedle() = default;

Eigen::VectorXd ClampedNeedle::reduce(const Eigen::MatrixX3d& field) const {
  Eigen::VectorXd r(free_dofs());
  for (int i = 0; i < free_dofs(); ++i) r[i] = field(free_dof_[static_cast<size_t>(i)] / 3, free_dof_[static_cast<size_t>(i)] % 3);
  return r;
}

Eigen::MatrixX3d ClampedNeedle::expand(const Eigen::VectorXd& reduced) const {
  Eigen::MatrixX3d field = Eigen::MatrixX3d::Zero(needle_.num_nodes(), 3);
  for (int i = 0; i < free_dofs(); ++i) field(free_dof_[static_cast<size_t>(i)] / 3, free_dof_[static_cast<size_t>(i)] % 3) = reduced[i];
  return field;
}

Eigen::MatrixX3d ClampedNeedle::solve(const Eigen::MatrixX3d& load_N) const {
  const Eigen::VectorXd u = factor_->llt.solve(reduce(load_N));
  if (!u.allFinite()) throw SolverError("the static solve gave non-finite displacements");
  return expand(u);
}

std::vector<VibrationMode> ClampedNeedle::lowest_modes(int count) const {
  NEEDLE_REQUIRE(count > 0 && count < free_dofs() / 2, "asked for an impossible number of modes");
  Eigen::MatrixX3d mass(needle_.num_nodes(), 3);
  for (int k = 0; k < 3; ++k) mass.col(k) = needle_.nodal_mass_g();
  const Eigen::VectorXd sqrt_mass = reduce(mass).cwiseSqrt();
  InverseStiffnessOperator op(factor_->llt, sqrt_mass);
  const int ncv = std::min(free_dofs() - 1, std::max(2 * count + 1, 20));
  Spectra::SymEigsSolver<InverseStiffnessOperator> eigs(op, count, ncv);
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestAlge, 1000, 1e-10);
  if (eigs.info() != Spectra::CompInfo::Successful) throw SolverError("the modal analysis did not converge");
  const Eigen::VectorXd values = eigs.eigenvalues();
  const Eigen::MatrixXd vectors = eigs.eigenvectors();
  std::vector<VibrationMode> modes;
  for (int i = 0; i < values.size(); ++i) {
    VibrationMode m;
    const double omega_per_ms = 1.0 / std::sqrt(values[i]);
    m.frequency_hz = omega_per_ms / (2.0 * M_PI) * 1000.0;
    m.shape = expand(vectors.col(i).cwiseQuotient(sqrt_mass));
    modes.push_back(std::move(m));
  }
  std::sort(modes.begin(), modes.end(), [](const VibrationMode& a, const VibrationMode& b) { return a.frequency_hz < b.frequency_hz; });
  return modes;
}

}  // namespace needle
