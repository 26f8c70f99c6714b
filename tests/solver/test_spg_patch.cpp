// Patch test of the SPG tissue: an affine motion gives the exact deformation gradient at every
// particle (regular and jittered sets), no smoothing defect, and zero residual force on the interior
// particles of a regular set; the internal forces always sum to zero (momentum).
#include <catch2/catch.hpp>
#include <algorithm>
#include <random>

#include "core/solver_error.h"
#include "solver/tissue/spg_tissue.h"
#include "tests/solver/solver_fixtures.h"

using namespace needle;

namespace {

TissueMaterial soft_card() {
  TissueMaterial m;
  m.E_MPa = 1.0;
  m.rate_law = RateLaw::off;
  return m;
}

}  // namespace

TEST_CASE("Patch test: affine motion gives the exact F and no stabilization force", "[solver][patch]") {
  Eigen::Matrix3d A;
  A << 0.02, -0.01, 0.005, 0.015, -0.01, 0.0, 0.004, 0.012, 0.008;
  const Eigen::Vector3d b(0.3, -0.2, 0.1);
  for (double jitter : {0.0, 0.3}) {
    const ParticleSet set = needle_test::jittered(needle_test::free_box({0, 0, 0}, {5, 5, 5}, 0.5), jitter);
    SpgTissue tissue(set, soft_card(), SpgOptions{});
    TissueParticles& p = tissue.particles();
    for (std::int64_t i = 0; i < p.size(); ++i) p.position_mm[static_cast<size_t>(i)] += A * p.reference_mm[static_cast<size_t>(i)] + b;
    tissue.compute_forces(1e-3);
    double worst_F = 0, worst_defect = 0;
    for (std::int64_t i = 0; i < p.size(); ++i) {
      worst_F = std::max(worst_F, (p.deformation_gradient[static_cast<size_t>(i)] - Eigen::Matrix3d::Identity() - A).norm());
      worst_defect = std::max(worst_defect, p.defect_mm[static_cast<size_t>(i)]);
    }
    INFO("jitter " << jitter);
    CHECK(worst_F < 1e-12);
    CHECK(worst_defect < 1e-12);
    // One stress everywhere.
    double stress_spread = 0;
    for (std::int64_t i = 0; i < p.size(); ++i) stress_spread = std::max(stress_spread, (p.stress_MPa[static_cast<size_t>(i)] - p.stress_MPa[0]).norm());
    REQUIRE(p.stress_MPa[0].norm() > 1e-3);
    CHECK(stress_spread < 1e-9 * p.stress_MPa[0].norm());
  }
}

TEST_CASE("Patch test: constant stress leaves the interior of a regular set in equilibrium", "[solver][patch]") {
  const ParticleSet set = needle_test::free_box({0, 0, 0}, {6, 6, 6}, 0.5);
  SpgTissue tissue(set, soft_card(), SpgOptions{});
  TissueParticles& p = tissue.particles();
  Eigen::Matrix3d A;
  A << 0.03, 0.01, 0.0, 0.01, -0.01, 0.02, 0.0, 0.02, 0.01;
  for (std::int64_t i = 0; i < p.size(); ++i) p.position_mm[static_cast<size_t>(i)] += A * p.reference_mm[static_cast<size_t>(i)];
  tissue.compute_forces(1e-3);
  // Force scale: one particle's share of a stress acting over a spacing.
  const double scale = p.stress_MPa[0].norm() * 0.125 / 0.5;
  REQUIRE(scale > 0);
  const double margin = 2 * 1.8 * 0.5 + 1e-9;  // two support radii: neither i nor its neighbours see the boundary
  double worst_interior = 0, worst_boundary = 0;
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (std::int64_t i = 0; i < p.size(); ++i) {
    const Eigen::Vector3d X = p.reference_mm[static_cast<size_t>(i)];
    const bool interior = (X.array() > margin).all() && (X.array() < 6 - margin).all();
    const double f = p.force_N[static_cast<size_t>(i)].norm();
    (interior ? worst_interior : worst_boundary) = std::max(interior ? worst_interior : worst_boundary, f);
    total += p.force_N[static_cast<size_t>(i)];
  }
  CHECK(worst_interior < 1e-10 * scale);
  CHECK(worst_boundary > 0.1 * scale);  // the free faces carry the traction: the check is not vacuous
  CHECK(total.norm() < 1e-10 * scale);
}

TEST_CASE("Internal forces sum to zero for any motion (linear momentum)", "[solver][patch]") {
  const ParticleSet set = needle_test::jittered(needle_test::free_box({0, 0, 0}, {4, 3, 3}, 0.5), 0.3);
  SpgTissue tissue(set, soft_card(), SpgOptions{});
  TissueParticles& p = tissue.particles();
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.02);
  for (auto& x : p.position_mm) x += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  tissue.compute_forces(1e-3);
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  double largest = 0;
  for (const auto& f : p.force_N) total += f, largest = std::max(largest, f.norm());
  REQUIRE(largest > 0);
  CHECK(total.norm() < 1e-12 * largest * static_cast<double>(p.size()));
}

TEST_CASE("Stresses updated ahead for the particles that stay give the forces of one evaluation, bit for bit", "[solver][patch][ahead]") {
  // Two copies of a jittered block through the same large, uneven motion (yield and the rate law active): one
  // evaluates its forces at once; the other updates the points of x < 2 mm ahead (told that those particles stay),
  // then evaluates. Every force, stress and state must be the same to the last bit; a particle flagged to stay
  // may not move until the evaluation, and the check says so.
  TissueMaterial card;
  card.E_MPa = 0.08;
  const ParticleSet set = needle_test::jittered(needle_test::free_box({0, 0, 0}, {4, 3, 3}, 0.5), 0.3);
  SpgTissue once(set, card, SpgOptions{}), ahead(set, card, SpgOptions{});
  std::vector<std::uint8_t> still(static_cast<size_t>(once.particles().size()));
  for (size_t i = 0; i < still.size(); ++i) still[i] = once.particles().reference_mm[i].x() < 2.0;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (int step = 0; step < 5; ++step) {
    std::vector<Eigen::Vector3d> shift(still.size());
    for (size_t i = 0; i < shift.size(); ++i) {
      const Eigen::Vector3d& X = once.particles().reference_mm[i];
      shift[i] = Eigen::Vector3d(0.4 * X.y(), 0.0, 0.05 * X.x()) + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    }
    for (SpgTissue* t : {&once, &ahead})
      for (size_t i = 0; i < shift.size(); ++i) t->particles().position_mm[i] += shift[i];
    const double dt = 1.0;  // slow enough for the rate law to let the card yield
    once.compute_forces(dt);
    const std::int64_t updated = ahead.update_points_ahead(dt, still);
    INFO("step " << step << ": " << updated << " of " << still.size() << " points updated ahead");
    CHECK(updated > 0);
    CHECK(updated < static_cast<std::int64_t>(std::count(still.begin(), still.end(), std::uint8_t{1})));  // rows reaching x >= 2 wait
    const size_t staying = static_cast<size_t>(std::find(still.begin(), still.end(), std::uint8_t{1}) - still.begin());
    const size_t moving = static_cast<size_t>(std::find(still.begin(), still.end(), std::uint8_t{0}) - still.begin());
    CHECK_THROWS_AS(ahead.check_may_move(static_cast<std::int64_t>(staying)), SolverError);
    CHECK_NOTHROW(ahead.check_may_move(static_cast<std::int64_t>(moving)));
    ahead.compute_forces(dt);
    CHECK_NOTHROW(ahead.check_may_move(static_cast<std::int64_t>(staying)));
    const TissueParticles &a = once.particles(), &b = ahead.particles();
    int differing = 0;
    for (size_t i = 0; i < still.size(); ++i)
      differing += a.force_N[i] != b.force_N[i] || a.stress_MPa[i] != b.stress_MPa[i] || a.deformation_gradient[i] != b.deformation_gradient[i] ||
                   a.plastic_strain[i] != b.plastic_strain[i] || a.elastic_left_cauchy_green[i] != b.elastic_left_cauchy_green[i] ||
                   a.effective_strain[i] != b.effective_strain[i];
    CHECK(differing == 0);
    if (step == 4) {
      double most_plastic = 0;
      for (double e : a.plastic_strain) most_plastic = std::max(most_plastic, e);
      INFO("yield strain " << card.yield_strain());
      CHECK(most_plastic > 0);  // the return mapping ran, not only the elastic update
    }
  }
}
