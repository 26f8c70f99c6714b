#include "solver/needle/fe_needle.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "core/input_error.h"
#include "core/parallel.h"
#include "mesher/tet_element.h"

namespace needle {
namespace {

using Mat3 = Eigen::Matrix3d;

using ElementDisplacements = Eigen::Matrix<double, 10, 3>;  // rows beyond npe unused (T4)

// The element's nodal displacements, gathered once for all its quadrature points.
ElementDisplacements element_displacements(const TetMesh& mesh, int e, const Eigen::MatrixX3d& x, int npe) {
  ElementDisplacements u;
  for (int a = 0; a < npe; ++a) u.row(a) = x.row(mesh.T(e, a)) - mesh.X.row(mesh.T(e, a));
  return u;
}

// Deformation gradient at one quadrature point: F = I + sum_a u_a (x) dN_a/dX.
Mat3 deformation_gradient(const double* dN, const ElementDisplacements& u, int npe) {
  Mat3 F = Mat3::Identity();
  for (int a = 0; a < npe; ++a) F += u.row(a).transpose() * Eigen::Map<const Eigen::RowVector3d>(dN + 3 * a);
  return F;
}

}  // namespace

FeNeedle::FeNeedle(TetMesh mesh, const NeedleMaterial& material, double mass_scaling_dt_ms)
    : mesh_(std::move(mesh)), material_(material) {
  material_.validate();
  NEEDLE_REQUIRE(mesh_.num_tets() > 0, "needle mesh has no elements");
  NEEDLE_REQUIRE(std::isfinite(mass_scaling_dt_ms) && mass_scaling_dt_ms >= 0,
                 "mass_scaling_dt_ms must be zero (off) or a positive time step");
  npe_ = mesh_.nodes_per_tet();
  const auto& rule = tet_quadrature(mesh_.order);
  qp_ = static_cast<int>(rule.size());
  const int ne = mesh_.num_tets();
  gradients_.assign(static_cast<size_t>(ne) * qp_ * npe_ * 3, 0.0);
  weights_.assign(static_cast<size_t>(ne) * qp_, 0.0);
  std::vector<Eigen::MatrixXd> reference_gradients;
  for (const auto& p : rule) reference_gradients.push_back(tet_shape_gradients(mesh_.order, p.xi));

  std::vector<int> bad;
  for (int e = 0; e < ne; ++e)
    for (int q = 0; q < qp_; ++q) {
      Mat3 J = Mat3::Zero();  // J_ij = d x_i / d xi_j
      for (int a = 0; a < npe_; ++a) J += mesh_.X.row(mesh_.T(e, a)).transpose() * reference_gradients[q].row(a);
      const double det = J.determinant();
      if (!(det > 0)) {
        bad.push_back(e);
        continue;
      }
      const Eigen::MatrixXd dNdX = reference_gradients[q] * J.inverse();
      double* out = &gradients_[(static_cast<size_t>(e) * qp_ + q) * npe_ * 3];
      for (int a = 0; a < npe_; ++a)
        for (int k = 0; k < 3; ++k) out[3 * a + k] = dNdX(a, k);
      weights_[static_cast<size_t>(e) * qp_ + q] = rule[q].weight * det;
    }
  NEEDLE_REQUIRE(bad.empty(), fmt::format("needle mesh: {} element(s) have a non-positive Jacobian (first: element {}); "
                                          "the mesh is inverted or too distorted for FE", bad.size(), bad.empty() ? -1 : bad[0]));

  // Node -> element slots (for the force gather).
  node_offsets_.assign(static_cast<size_t>(num_nodes()) + 1, 0);
  for (int e = 0; e < ne; ++e)
    for (int a = 0; a < npe_; ++a) ++node_offsets_[static_cast<size_t>(mesh_.T(e, a)) + 1];
  for (size_t i = 1; i < node_offsets_.size(); ++i) node_offsets_[i] += node_offsets_[i - 1];
  node_slots_.resize(static_cast<size_t>(node_offsets_.back()));
  std::vector<int> fill(node_offsets_.begin(), node_offsets_.end() - 1);
  for (int e = 0; e < ne; ++e)
    for (int a = 0; a < npe_; ++a) node_slots_[static_cast<size_t>(fill[static_cast<size_t>(mesh_.T(e, a))]++)] = e * npe_ + a;
  element_forces_.assign(static_cast<size_t>(ne) * npe_ * 3, 0.0);
  element_energy_.assign(static_cast<size_t>(ne), 0.0);

  // Lumped masses and each element's own stable step, 2 / sqrt(lambda_max(M_e^-1/2 K_e M_e^-1/2)).
  const std::vector<double>& fractions = tet_lumped_mass_fractions(mesh_.order);
  std::vector<double> element_mass(static_cast<size_t>(ne)), element_dt(static_cast<size_t>(ne));
  parallel_for(ne, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t e = begin; e < end; ++e) {
      double volume = 0;
      for (int q = 0; q < qp_; ++q) volume += weight(static_cast<int>(e), q);
      const double m = material_.density_g_per_mm3 * volume;
      element_mass[static_cast<size_t>(e)] = m;
      Eigen::VectorXd inv_sqrt_mass(3 * npe_);
      for (int a = 0; a < npe_; ++a) inv_sqrt_mass.segment<3>(3 * a).setConstant(1.0 / std::sqrt(m * fractions[static_cast<size_t>(a)]));
      const Eigen::MatrixXd A = inv_sqrt_mass.asDiagonal() * element_stiffness(static_cast<int>(e)) * inv_sqrt_mass.asDiagonal();
      const double lambda_max = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
      element_dt[static_cast<size_t>(e)] = 2.0 / std::sqrt(lambda_max);
    }
  });
  nodal_mass_ = Eigen::VectorXd::Zero(num_nodes());
  unscaled_dt_ms_ = *std::min_element(element_dt.begin(), element_dt.end());
  stable_dt_ms_ = std::numeric_limits<double>::infinity();
  for (int e = 0; e < ne; ++e) {
    double m = element_mass[static_cast<size_t>(e)];
    physical_mass_ += m;
    double dt = element_dt[static_cast<size_t>(e)];
    if (mass_scaling_dt_ms > 0 && dt < mass_scaling_dt_ms) {
      m *= (mass_scaling_dt_ms / dt) * (mass_scaling_dt_ms / dt);
      dt = mass_scaling_dt_ms;
      ++mass_scaled_elements_;
    }
    stable_dt_ms_ = std::min(stable_dt_ms_, dt);
    for (int a = 0; a < npe_; ++a) nodal_mass_[mesh_.T(e, a)] += m * fractions[static_cast<size_t>(a)];
  }
  NEEDLE_REQUIRE((nodal_mass_.array() > 0).all(), "needle mesh has nodes that belong to no element");
}

Eigen::MatrixXd FeNeedle::element_stiffness(int e) const {
  const double mu = material_.shear_modulus_MPa(), lambda = material_.lame_lambda_MPa();
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(3 * npe_, 3 * npe_);
  for (int q = 0; q < qp_; ++q) {
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> G(gradients(e, q), npe_, 3);
    const double w = weight(e, q);
    for (int a = 0; a < npe_; ++a)
      for (int b = 0; b < npe_; ++b) {
        const Eigen::Vector3d ga = G.row(a).transpose(), gb = G.row(b).transpose();
        K.block<3, 3>(3 * a, 3 * b) += w * (lambda * ga * gb.transpose() + mu * gb * ga.transpose() +
                                             mu * ga.dot(gb) * Mat3::Identity());
      }
  }
  return K;
}

double FeNeedle::internal_forces(const Eigen::MatrixX3d& x, Eigen::MatrixX3d& force) const {
  const double mu = material_.shear_modulus_MPa(), lambda = material_.lame_lambda_MPa();
  const int ne = num_elements();
  parallel_for(ne, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t e = begin; e < end; ++e) {
      const ElementDisplacements u = element_displacements(mesh_, static_cast<int>(e), x, npe_);
      double* fe = &element_forces_[static_cast<size_t>(e) * npe_ * 3];
      std::fill(fe, fe + npe_ * 3, 0.0);
      double energy = 0;
      for (int q = 0; q < qp_; ++q) {
        const double* dN = gradients(static_cast<int>(e), q);
        const Mat3 F = deformation_gradient(dN, u, npe_);
        const Mat3 E = 0.5 * (F.transpose() * F - Mat3::Identity());
        const double trE = E.trace();
        const Mat3 S = lambda * trE * Mat3::Identity() + 2.0 * mu * E;
        const double w = weight(static_cast<int>(e), q);
        energy += w * (0.5 * lambda * trE * trE + mu * E.squaredNorm());
        const Mat3 P = w * F * S;
        for (int a = 0; a < npe_; ++a) {
          const Eigen::Map<const Eigen::Vector3d> g(dN + 3 * a);
          const Eigen::Vector3d f = -P * g;
          fe[3 * a] += f.x();
          fe[3 * a + 1] += f.y();
          fe[3 * a + 2] += f.z();
        }
      }
      element_energy_[static_cast<size_t>(e)] = energy;
    }
  });
  force.resize(num_nodes(), 3);
  parallel_for(num_nodes(), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t n = begin; n < end; ++n) {
      Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
      for (int s = node_offsets_[static_cast<size_t>(n)]; s < node_offsets_[static_cast<size_t>(n) + 1]; ++s) {
        const double* f = &element_forces_[static_cast<size_t>(node_slots_[static_cast<size_t>(s)]) * 3];
        sum += Eigen::RowVector3d(f[0], f[1], f[2]);
      }
      force.row(n) = sum;
    }
  });
  double energy = 0;
  for (double w : element_energy_) energy += w;
  return energy;
}

Eigen::SparseMatrix<double> FeNeedle::stiffness_matrix() const {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(num_elements()) * 9 * npe_ * npe_);
  for (int e = 0; e < num_elements(); ++e) {
    const Eigen::MatrixXd K = element_stiffness(e);
    for (int a = 0; a < npe_; ++a)
      for (int b = 0; b < npe_; ++b)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            triplets.emplace_back(3 * mesh_.T(e, a) + i, 3 * mesh_.T(e, b) + j, K(3 * a + i, 3 * b + j));
  }
  Eigen::SparseMatrix<double> K(3 * num_nodes(), 3 * num_nodes());
  K.setFromTriplets(triplets.begin(), triplets.end());
  return K;
}

ElementStresses FeNeedle::element_stresses(const Eigen::MatrixX3d& x) const {
  const double mu = material_.shear_modulus_MPa(), lambda = material_.lame_lambda_MPa();
  ElementStresses out;
  out.von_mises_MPa.resize(num_elements());
  out.cauchy_MPa.resize(num_elements(), 6);
  parallel_for(num_elements(), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t e = begin; e < end; ++e) {
      const ElementDisplacements u = element_displacements(mesh_, static_cast<int>(e), x, npe_);
      Mat3 mean = Mat3::Zero();
      double vm = 0;
      for (int q = 0; q < qp_; ++q) {
        const Mat3 F = deformation_gradient(gradients(static_cast<int>(e), q), u, npe_);
        const Mat3 E = 0.5 * (F.transpose() * F - Mat3::Identity());
        const Mat3 S = lambda * E.trace() * Mat3::Identity() + 2.0 * mu * E;
        const Mat3 sigma = F * S * F.transpose() / F.determinant();
        const Mat3 dev = sigma - sigma.trace() / 3.0 * Mat3::Identity();
        vm += std::sqrt(1.5 * dev.squaredNorm()) / qp_;
        mean += sigma / qp_;
      }
      out.von_mises_MPa[e] = vm;
      out.cauchy_MPa.row(e) << mean(0, 0), mean(1, 1), mean(2, 2), mean(0, 1), mean(1, 2), mean(2, 0);
    }
  });
  return out;
}

}  // namespace needle
