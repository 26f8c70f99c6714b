// The tissue's integrator in its two halves (tissue/tissue_dynamics.h), as the coupled step drives it:
// kick_and_drift then finish_step is step() to the last bit; a uniform external load accelerates a free block
// as a rigid body (momentum F t, position F t^2 / 2m, the load's work equal to the kinetic energy); and the
// halves refuse to be called out of order.
#include <catch2/catch.hpp>
#include <cmath>

#include "core/input_error.h"
#include "solver/tissue/spg_tissue.h"
#include "solver/tissue/tissue_dynamics.h"
#include "tests/solver/solver_fixtures.h"

using namespace needle;

namespace {

// A free block given an initial shear velocity field, so that its internal forces are not zero.
SpgTissue sheared_block() {
  SpgTissue tissue(needle_test::free_box({0, 0, 0}, {2.0, 1.2, 1.2}, 0.2), TissueMaterial{}, SpgOptions{});
  TissueParticles& p = tissue.particles();
  for (std::int64_t i = 0; i < p.size(); ++i) p.velocity_mm_per_ms[static_cast<size_t>(i)] = Vec3d(0, 0.5 * p.position_mm[static_cast<size_t>(i)].x(), 0);
  return tissue;
}

}  // namespace

TEST_CASE("The tissue's two half steps are its whole step, bit for bit", "[solver][spg][dynamics]") {
  SpgTissue a = sheared_block(), b = sheared_block();
  TissueDynamics whole(a, {}), halves(b, {});
  for (int k = 0; k < 40; ++k) {
    whole.step();
    halves.kick_and_drift();
    halves.finish_step(nullptr);
  }
  CHECK(whole.time_ms() == halves.time_ms());
  for (std::int64_t i = 0; i < a.particles().size(); ++i) {
    const size_t s = static_cast<size_t>(i);
    REQUIRE(a.particles().position_mm[s] == b.particles().position_mm[s]);
    REQUIRE(a.particles().velocity_mm_per_ms[s] == b.particles().velocity_mm_per_ms[s]);
  }
  CHECK(whole.energy().model_work_mJ == halves.energy().model_work_mJ);
  CHECK(whole.energy().kinetic_mJ == halves.energy().kinetic_mJ);
  CHECK(whole.energy().relative_error() < 1e-3);
}

TEST_CASE("A uniform external load accelerates a free block as a rigid body, its work all kinetic energy", "[solver][spg][dynamics]") {
  SpgTissue tissue(needle_test::free_box({0, 0, 0}, {2.0, 1.2, 1.2}, 0.2), TissueMaterial{}, SpgOptions{});
  TissueParticles& p = tissue.particles();
  const size_t n = static_cast<size_t>(p.size());
  // Force per particle proportional to its mass: every particle gets the same acceleration a.
  const Vec3d a(0.0, 2.0, -1.0);  // mm/ms^2
  std::vector<Vec3d> load(n);
  double mass = 0;
  for (size_t i = 0; i < n; ++i) {
    load[i] = p.mass_g[i] * a;
    mass += p.mass_g[i];
  }
  const std::vector<Vec3d> start = p.position_mm;
  TissueDynamics dynamics(tissue, {});
  dynamics.set_external_forces(load);
  for (int k = 0; k < 50; ++k) {
    dynamics.kick_and_drift(0.01);
    dynamics.finish_step(&load);
  }
  const double t = dynamics.time_ms();
  Vec3d momentum = Vec3d::Zero();
  double worst_position = 0, worst_force = 0;
  for (size_t i = 0; i < n; ++i) {
    momentum += p.mass_g[i] * p.velocity_mm_per_ms[i];
    worst_position = std::max(worst_position, (p.position_mm[i] - start[i] - 0.5 * t * t * a).norm());
    worst_force = std::max(worst_force, p.force_N[i].norm());
  }
  INFO("t " << t << " ms; momentum " << momentum.transpose() << "; worst position error " << worst_position << " mm");
  CHECK((momentum - mass * t * a).norm() < 1e-9 * mass * t * a.norm());
  CHECK(worst_position < 1e-9);
  CHECK(worst_force < 1e-9 * p.mass_g[0] * a.norm());  // no deformation, no internal force
  CHECK(dynamics.energy().external_work_mJ == Approx(dynamics.energy().kinetic_mJ).epsilon(1e-9));
  CHECK(dynamics.energy().relative_error() < 1e-9);
}

TEST_CASE("The tissue's half steps refuse to run out of order", "[solver][spg][dynamics]") {
  SpgTissue tissue = sheared_block();
  TissueDynamics dynamics(tissue, {});
  CHECK_THROWS_AS(dynamics.finish_step(nullptr), InputError);
  dynamics.kick_and_drift();
  CHECK_THROWS_AS(dynamics.kick_and_drift(), InputError);
  CHECK_THROWS_AS(dynamics.set_external_forces(std::vector<Vec3d>(static_cast<size_t>(tissue.particles().size()), Vec3d::Zero())), InputError);
  const std::vector<Vec3d> three(3, Vec3d::Zero());
  CHECK_THROWS_AS(dynamics.finish_step(&three), InputError);  // one force per particle, or nothing
  dynamics.finish_step(nullptr);  // the step is still there to finish
  CHECK(dynamics.steps() == 1);
}
