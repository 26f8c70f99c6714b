// The Hencky strain's series against the eigenvalue logarithm, and the stress update that uses it (an elastic
// trial near the identity) against the same update in principal axes, for both laws and the viscoelastic branch.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "solver/tissue/hencky_strain.h"
#include "solver/tissue/tissue_material.h"

using namespace needle;

namespace {

// A random rotation and principal values: Q diag(v) Q^T.
Eigen::Matrix3d spd_with_eigenvalues(const Eigen::Vector3d& v, std::mt19937& rng) {
  std::normal_distribution<double> normal;
  const Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  const Eigen::Matrix3d Q = q.normalized().toRotationMatrix();
  return Q * v.asDiagonal() * Q.transpose();
}

Eigen::Matrix3d log_by_eigenvalues(const Eigen::Matrix3d& b) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(b);
  return eig.eigenvectors() * eig.eigenvalues().array().log().matrix().asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace

TEST_CASE("The Hencky strain's series is half the logarithm of b near the identity, and declines beyond its limit", "[solver][material]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  int summed = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    // Principal log strains from 1e-9 to 0.3 (beyond the limit for the larger ones), some nearly equal.
    const double scale = std::pow(10.0, -9 + 8.5 * (trial % 100) / 100.0);
    Eigen::Vector3d h(unit(rng), unit(rng), unit(rng));
    if (trial % 3 == 0) h[1] = h[0] * (1 + 1e-12);
    h *= scale;
    const Eigen::Matrix3d b = spd_with_eigenvalues((2 * h).array().exp().matrix(), rng);
    Eigen::Matrix3d H = Eigen::Matrix3d::Constant(-7);
    const bool ok = hencky_strain_near_identity(b, H);
    const double y_norm = ((b - Eigen::Matrix3d::Identity()) * (b + Eigen::Matrix3d::Identity()).inverse()).norm();
    if (y_norm > kHenckySeriesLimit * (1 + 1e-12)) {
      CHECK_FALSE(ok);
      CHECK(H == Eigen::Matrix3d::Constant(-7));  // untouched
      continue;
    }
    if (y_norm < kHenckySeriesLimit * (1 - 1e-12)) REQUIRE(ok);
    if (!ok) continue;
    ++summed;
    // Against the eigenvalue logarithm of b, and against the principal values b was built from (up to b's own
    // rounding, about 1e-15 absolute).
    const Eigen::Matrix3d expected = 0.5 * log_by_eigenvalues(b);
    CHECK((H - expected).norm() <= 1e-15 + 1e-14 * expected.norm());
    CHECK(std::abs(H.trace() - h.sum()) <= 4e-15 + 1e-13 * h.norm());
    CHECK(H.norm() == Approx(h.norm()).epsilon(1e-12).margin(4e-15));
    CHECK((H - H.transpose()).norm() == 0);
  }
  CHECK(summed > 1000);
  // Not finite, or far from the identity: declined.
  Eigen::Matrix3d H;
  CHECK_FALSE(hencky_strain_near_identity(Eigen::Matrix3d::Identity() * std::nan(""), H));
  CHECK_FALSE(hencky_strain_near_identity(Eigen::Vector3d(2.0, 1.0, 1.0).asDiagonal(), H));
  REQUIRE(hencky_strain_near_identity(Eigen::Matrix3d::Identity(), H));
  CHECK(H.norm() == 0);
}

TEST_CASE("An elastic trial near the identity updates as in principal axes, for both laws and the Maxwell branch", "[solver][material]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1, 1);
  TissueMaterial mat018;
  mat018.E_MPa = 0.0884;
  TissueMaterial stiffening = mat018;
  stiffening.law = TissueLaw::stiffening_elastic;
  TissueMaterial relaxing = mat018;
  relaxing.relaxing_shear_fraction = 0.4;
  relaxing.relaxation_time_ms = 0.5;
  TissueMaterial yielding = mat018;  // k eps^n meets E eps at 0.06: within the series' reach
  yielding.k_MPa = 12;
  yielding.rate_law = RateLaw::off;
  TissueMaterial capping = mat018;  // the printed rate law's exponent 10 reaches the cap at these increments' rates
  capping.rate_law = RateLaw::printed;
  int compared = 0, flowed = 0, capped = 0;
  for (const TissueMaterial& m : {mat018, stiffening, relaxing, yielding, capping}) {
    m.validate();
    for (int trial = 0; trial < 600; ++trial) {
      MaterialPoint state;
      const double strain = 0.12 * (trial % 60) / 60.0;  // up to the series' limit and through MAT_018's yield
      state.elastic_left_cauchy_green = spd_with_eigenvalues(Eigen::Vector3d(std::exp(2 * strain * unit(rng)), std::exp(2 * strain * unit(rng)),
                                                                             std::exp(2 * strain * unit(rng))),
                                                             rng);
      state.plastic_strain = trial % 4 == 0 ? 0.05 : 0.0;
      if (m.viscoelastic()) {
        state.relaxed_stress_MPa = spd_with_eigenvalues(Eigen::Vector3d(unit(rng), unit(rng), unit(rng)) * 1e-3, rng);
        state.elastic_deviator_MPa = spd_with_eigenvalues(Eigen::Vector3d(unit(rng), unit(rng), unit(rng)) * 1e-3, rng);
      }
      Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) f(r, c) += 0.01 * unit(rng);
      const double dt_ms = trial % 2 ? 0.002 : 0.02;
      const StressUpdate fast = update_stress(m, state, f, dt_ms);
      const StressUpdate principal = update_stress_by_eigenvalues(m, state, f, dt_ms);
      flowed += principal.state.plastic_strain > state.plastic_strain;
      capped += principal.rate_factor_capped;
      const double scale = principal.cauchy_stress_MPa.norm() + m.E_MPa * 1e-12;
      CHECK((fast.cauchy_stress_MPa - principal.cauchy_stress_MPa).norm() <= 1e-12 * scale);
      CHECK((fast.state.elastic_left_cauchy_green - principal.state.elastic_left_cauchy_green).norm() <= 1e-13);
      CHECK(fast.state.plastic_strain == Approx(principal.state.plastic_strain).epsilon(1e-12).margin(1e-15));
      CHECK(fast.effective_strain == Approx(principal.effective_strain).epsilon(1e-12).margin(1e-14));
      CHECK(fast.rate_factor_capped == principal.rate_factor_capped);
      CHECK((fast.state.relaxed_stress_MPa - principal.state.relaxed_stress_MPa).norm() <= 1e-12 * scale);
      ++compared;
    }
  }
  CHECK(compared == 3000);
  // The trials reach MAT_018's yield and its rate cap, where the update takes the principal axes itself.
  CHECK(flowed > 50);
  CHECK(capped > 50);
}
