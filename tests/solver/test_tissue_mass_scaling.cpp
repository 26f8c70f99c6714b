// The tissue's selective mass scaling (tissue/tissue_mass_scaling.h): a squeezed particle gets the mass that
// brings its own step to the target, m0 (dt / dt_i)^2, keeping its momentum, and its physical mass back (with
// its velocity) once released; a bar whose every particle is scaled ninefold vibrates three times slower and
// keeps its energy account.
#include <catch2/catch.hpp>
#include <cmath>

#include "solver/tissue/spg_tissue.h"
#include "solver/tissue/tissue_dynamics.h"
#include "solver/tissue/tissue_mass_scaling.h"
#include "tests/solver/solver_fixtures.h"

using namespace needle;

namespace {

TissueMaterial elastic_card() {
  TissueMaterial m;
  m.E_MPa = 1.0;
  m.nu = 0.3;
  m.rate_law = RateLaw::off;
  return m;
}

// Time of the first sign change of the mean x velocity of the layer at x = 0 (a quarter period of the bar's
// first mode), linearly interpolated between steps.
double quarter_period_ms(double target_dt_ms) {
  const double L = 20.0;
  SpgTissue tissue(needle_test::free_box({0, 0, 0}, {L, 2, 2}, 0.5), elastic_card(), SpgOptions{});
  TissueParticles& p = tissue.particles();
  std::vector<size_t> end_layer;
  for (std::int64_t i = 0; i < p.size(); ++i) {
    const size_t s = static_cast<size_t>(i);
    p.velocity_mm_per_ms[s].x() = 0.03 * std::cos(M_PI * p.reference_mm[s].x() / L);
    if (p.reference_mm[s].x() < 1e-9) end_layer.push_back(s);
  }
  TissueDynamics dynamics(tissue, {});
  if (target_dt_ms > 0) dynamics.set_mass_scaling(target_dt_ms);
  const auto mean_vx = [&] {
    double v = 0;
    for (size_t s : end_layer) v += p.velocity_mm_per_ms[s].x();
    return v / static_cast<double>(end_layer.size());
  };
  double t_prev = 0, v_prev = mean_vx(), worst_balance = 0, first_scaling_mJ = 0, kinetic_after_first_mJ = 0;
  for (int k = 0; k < 100000; ++k) {
    dynamics.step();
    if (k == 0) {
      // The first step gives the moving bar its masses: momentum kept, so its kinetic energy drops to a ninth.
      first_scaling_mJ = dynamics.energy().mass_scaling_mJ;
      kinetic_after_first_mJ = dynamics.energy().kinetic_mJ;
    }
    worst_balance = std::max(worst_balance, dynamics.energy().relative_error());
    const double v = mean_vx();
    if (v < 0) {
      const EnergyBalance& e = dynamics.energy();
      INFO("target " << target_dt_ms << " ms: balance error " << worst_balance << "; mass-scaling energy " << first_scaling_mJ
                     << " mJ in the first step of " << e.initial_kinetic_mJ << ", then " << e.mass_scaling_mJ - first_scaling_mJ);
      CHECK(worst_balance < 1e-3);
      if (target_dt_ms > 0) CHECK(first_scaling_mJ == Approx((1.0 / 9 - 1) * e.initial_kinetic_mJ).epsilon(0.01));
      else CHECK(e.mass_scaling_mJ == 0);
      // After it the masses barely change (strains of 1e-3): almost nothing more is removed, nothing made.
      CHECK(e.mass_scaling_mJ - first_scaling_mJ <= 0);
      CHECK(first_scaling_mJ - e.mass_scaling_mJ < 1e-3 * kinetic_after_first_mJ);
      return t_prev + (dynamics.time_ms() - t_prev) * v_prev / (v_prev - v);
    }
    t_prev = dynamics.time_ms(), v_prev = v;
  }
  FAIL("the bar's end never turned");
  return 0;
}

}  // namespace

TEST_CASE("A squeezed particle gets mass m0 (dt/dt_i)^2 with its momentum, released, its physical mass with its velocity",
          "[solver][spg][dynamics]") {
  SpgTissue tissue(needle_test::free_box({0, 0, 0}, {2, 2, 2}, 0.5), elastic_card(), SpgOptions{});
  TissueParticles& p = tissue.particles();
  const std::vector<double> m0 = p.mass_g;
  const double dt0 = tissue.stable_time_step_ms();  // undeformed: every particle's own step
  std::vector<double> own;
  tissue.particle_time_steps_ms(own);
  for (double dt : own) CHECK(dt == Approx(dt0).epsilon(1e-12));
  // A homogeneous squeeze to half the length in x: F = diag(0.5, 1, 1) exactly (the RK gradients reproduce
  // linear fields), so every particle's step halves.
  for (auto& x : p.position_mm) x.x() *= 0.5;
  tissue.compute_forces(0.0);
  tissue.particle_time_steps_ms(own);
  for (double dt : own) CHECK(dt == Approx(0.5 * dt0).epsilon(1e-9));
  const Vec3d v0(0.3, -0.2, 0.1);
  for (auto& v : p.velocity_mm_per_ms) v = v0;
  TissueMassScaling scaling(0.8 * dt0, p);
  CHECK(scaling.time_step_ms(0.5 * dt0) == 0.8 * dt0);
  CHECK(scaling.time_step_ms(dt0) == dt0);
  const std::vector<std::uint8_t> free_mask(static_cast<size_t>(p.size()), 0);
  const double ratio = (0.8 / 0.5) * (0.8 / 0.5);
  // Every other particle crushed: the crushed share of the report is theirs alone.
  double physical_crushed = 0;
  for (size_t s = 0; s < m0.size(); s += 2) {
    p.flags[s] |= kParticleCrushed;
    physical_crushed += m0[s];
  }
  CHECK(scaling.apply(0.8 * dt0, tissue, p, free_mask).size() == static_cast<size_t>(p.size()));
  CHECK(scaling.report().max_ratio_crushed == Approx(ratio).epsilon(1e-9));
  CHECK(scaling.report().max_added_mass_crushed_g == Approx((ratio - 1) * physical_crushed).epsilon(1e-9));
  for (size_t s = 0; s < m0.size(); s += 2) p.flags[s] &= static_cast<std::uint8_t>(~kParticleCrushed);
  double physical = 0;
  for (size_t s = 0; s < m0.size(); ++s) {
    physical += m0[s];
    CHECK(p.mass_g[s] == Approx(ratio * m0[s]).epsilon(1e-9));
    CHECK((p.mass_g[s] * p.velocity_mm_per_ms[s] - m0[s] * v0).norm() < 1e-12 * m0[s] * v0.norm());  // momentum kept
  }
  CHECK(scaling.report().scaled_particles == p.size());
  CHECK(scaling.report().added_mass_g == Approx((ratio - 1) * physical).epsilon(1e-9));
  CHECK(scaling.report().max_ratio == Approx(ratio).epsilon(1e-9));
  // Released: physical masses, velocities kept; the energy the two changes removed is the closed form.
  for (size_t s = 0; s < m0.size(); ++s) p.position_mm[s] = p.reference_mm[s];
  tissue.compute_forces(0.0);
  scaling.apply(0.8 * dt0, tissue, p, free_mask);
  for (size_t s = 0; s < m0.size(); ++s) {
    CHECK(p.mass_g[s] == m0[s]);
    CHECK((p.velocity_mm_per_ms[s] - v0 / ratio).norm() < 1e-12 * v0.norm());
  }
  CHECK(scaling.report().scaled_particles == 0);
  CHECK(scaling.report().added_mass_g == 0);
  const double gained = 0.5 * physical * v0.squaredNorm() * (1 / ratio - 1);
  const double released = -0.5 * (ratio - 1) * physical * (v0 / ratio).squaredNorm();
  CHECK(scaling.report().energy_mJ == Approx(gained + released).epsilon(1e-9));
  // A constrained component keeps its prescribed velocity when the particle gains mass.
  for (auto& x : p.position_mm) x.x() *= 0.5;
  tissue.compute_forces(0.0);
  for (auto& v : p.velocity_mm_per_ms) v = v0;
  const std::vector<std::uint8_t> z_held(static_cast<size_t>(p.size()), 4);
  scaling.apply(0.8 * dt0, tissue, p, z_held);
  CHECK(p.velocity_mm_per_ms[0].z() == v0.z());
  CHECK(p.velocity_mm_per_ms[0].x() == Approx(v0.x() / ratio).epsilon(1e-12));
}

TEST_CASE("A bar mass-scaled ninefold throughout vibrates three times slower and keeps its energy account", "[solver][spg][dynamics]") {
  const double dt0 = SpgTissue(needle_test::free_box({0, 0, 0}, {20, 2, 2}, 0.5), elastic_card(), SpgOptions{}).stable_time_step_ms();
  const double plain = quarter_period_ms(0.0);
  const double scaled = quarter_period_ms(3 * dt0);  // every particle's own step is about dt0: masses x 9
  INFO("quarter period " << plain << " ms unscaled, " << scaled << " ms at three times the step");
  CHECK(scaled / plain == Approx(3.0).epsilon(0.01));
}
