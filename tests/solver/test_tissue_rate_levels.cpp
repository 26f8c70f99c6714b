// Multi-rate stepping of the tissue (solver/tissue/tissue_rate_levels.h): a block whose one half steps at the
// base step and whose other half updates its stresses every fourth step. Checked against what holds exactly or
// what the single-rate integrator gives on the same work: momentum (exact, each point's forces sum to zero), the
// total energy of an undamped vibration (kinetic + stored Hencky energy + the stabilisation's), and a pulse that
// crosses from the fast half into the slow one (its speed, and the reflection the interface sends back).
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "solver/tissue/tissue_dynamics.h"
#include "tests/solver/solver_fixtures.h"

using namespace needle;

namespace {

using needle_test::elastic_card;

// The particles with x below x_fast_mm are held at the base step.
std::vector<std::uint8_t> fast_below(const TissueParticles& p, double x_fast_mm) {
  std::vector<std::uint8_t> fast(static_cast<size_t>(p.size()));
  for (std::int64_t i = 0; i < p.size(); ++i) fast[static_cast<size_t>(i)] = p.initial_mm[static_cast<size_t>(i)].x() < x_fast_mm;
  return fast;
}

// Stored elastic energy, sum over points of V0 (G |dev eps|^2 + K/2 tr(eps)^2) with eps = ln(b_e) / 2 (the
// Hencky law's, whose Kirchhoff stress is its derivative), plus the smoothing penalty's.
double stored_energy_mJ(const SpgTissue& tissue) {
  const TissueParticles& p = tissue.particles();
  const TissueMaterial& m = tissue.material();
  const double G = m.shear_modulus_MPa(), K = m.bulk_modulus_MPa();
  double energy = tissue.stabilization_energy_mJ();
  for (std::int64_t i = 0; i < p.size(); ++i) {
    const size_t s = static_cast<size_t>(i);
    Eigen::SelfAdjointEigenSolver<Mat3d> eig(p.elastic_left_cauchy_green[s]);
    const Eigen::Vector3d e = 0.5 * eig.eigenvalues().array().log();
    const double trace = e.sum();
    const Eigen::Vector3d dev = e.array() - trace / 3;
    energy += p.reference_volume_mm3[s] * (G * dev.squaredNorm() + 0.5 * K * trace * trace);
  }
  return energy;
}

Eigen::Vector3d momentum(const TissueParticles& p) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::int64_t i = 0; i < p.size(); ++i) sum += p.mass_g[static_cast<size_t>(i)] * p.velocity_mm_per_ms[static_cast<size_t>(i)];
  return sum;
}

}  // namespace

TEST_CASE("Rate levels: each particle's level is the largest power of two of base steps within its own stable step",
          "[solver][dynamics][multirate]") {
  SpgTissue tissue(needle_test::free_box({0, 0, 0}, {4, 2, 2}, 0.5), elastic_card(0.3), SpgOptions{});
  TissueRateLevels levels(3);
  std::vector<double> own;
  tissue.particle_time_steps_ms(own);
  const double base = *std::min_element(own.begin(), own.end()) / 5.0;  // every particle at least 5 base steps
  const std::vector<std::uint8_t>& l = levels.levels(tissue, base);
  for (size_t s = 0; s < own.size(); ++s) {
    const int expected = std::min(3, static_cast<int>(std::floor(std::log2(own[s] / base))));
    CHECK(static_cast<int>(l[s]) == expected);
    CHECK(std::ldexp(base, l[s]) <= own[s]);
  }
  levels.set_fast_particles(fast_below(tissue.particles(), 2.0));
  const std::vector<std::uint8_t>& held = levels.levels(tissue, base);
  for (std::int64_t i = 0; i < tissue.particles().size(); ++i)
    if (tissue.particles().initial_mm[static_cast<size_t>(i)].x() < 2.0) CHECK(held[static_cast<size_t>(i)] == 0);
  // A safety factor of 2: every period within half the particle's own step.
  TissueRateLevels careful(3, 2.0);
  const std::vector<std::uint8_t>& halved = careful.levels(tissue, base);
  for (size_t s = 0; s < own.size(); ++s) {
    CHECK(static_cast<int>(halved[s]) == std::clamp(static_cast<int>(std::floor(std::log2(own[s] / (2 * base)))), 0, 3));
    CHECK(std::ldexp(base, halved[s]) <= 0.5 * own[s]);
  }
  CHECK_THROWS(TissueRateLevels(0));
  CHECK_THROWS(TissueRateLevels(11));
  CHECK_THROWS(TissueRateLevels(2, 0.5));
}

TEST_CASE("Rate levels: a free block's momentum is kept exactly across the interface between rates", "[solver][dynamics][multirate]") {
  SpgTissue tissue(needle_test::jittered(needle_test::free_box({0, 0, 0}, {6, 2, 2}, 0.5), 0.15), elastic_card(0.3), SpgOptions{});
  TissueParticles& p = tissue.particles();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double c = std::sqrt(tissue.material().p_wave_modulus_MPa() / tissue.material().density_g_per_mm3());
  for (Vec3d& v : p.velocity_mm_per_ms) v = 1e-2 * c * Vec3d(u(rng), u(rng), u(rng));
  TissueDynamics dynamics(tissue, {});
  dynamics.set_rate_levels(2);
  dynamics.set_fast_particles(fast_below(p, 3.0));
  const double base = tissue.stable_time_step_ms() / 4.5;
  const Eigen::Vector3d p0 = momentum(p);
  double scale = 0;
  for (std::int64_t i = 0; i < p.size(); ++i) scale += p.mass_g[static_cast<size_t>(i)] * p.velocity_mm_per_ms[static_cast<size_t>(i)].norm();
  for (int k = 0; k < 400; ++k) dynamics.step(base);
  REQUIRE(tissue.multirate());
  // Both rates took part: some points slow, some fast.
  const std::vector<double>& shares = dynamics.rate_levels()->last_point_level_shares();
  INFO("point shares by level: " << shares[0] << ", " << shares[1] << ", " << shares[2]);
  CHECK(shares[0] > 0.3);
  CHECK(shares[2] > 0.3);
  const double drift = (momentum(p) - p0).norm() / scale;
  INFO("momentum drift / sum m|v|: " << drift);
  CHECK(drift < 1e-13);
}

TEST_CASE("Rate levels: an undamped vibration across two rates keeps its total energy", "[solver][dynamics][multirate][slow]") {
  // The bar's first mode (strain amplitude ~1e-3, elastic), its left half at the base step, its right half's
  // stresses every fourth step: kinetic + stored energy at the ends of the cycles, against the single rate's.
  const double L = 20.0;
  auto run = [&](int max_level, double& worst_drift, double& ke_ratio) {
    SpgTissue tissue(needle_test::free_box({0, 0, 0}, {L, 2, 2}, 0.5), elastic_card(0.3), SpgOptions{});
    TissueParticles& p = tissue.particles();
    const double c = std::sqrt(tissue.material().E_MPa / tissue.material().density_g_per_mm3());
    const double v0 = 1e-3 * c;
    for (std::int64_t i = 0; i < p.size(); ++i)
      p.velocity_mm_per_ms[static_cast<size_t>(i)].x() = v0 * std::cos(M_PI * p.reference_mm[static_cast<size_t>(i)].x() / L);
    TissueDynamics dynamics(tissue, {});
    if (max_level > 0) {
      dynamics.set_rate_levels(max_level);
      dynamics.set_fast_particles(fast_below(p, 0.5 * L));
    }
    const double base = tissue.stable_time_step_ms() / 4.5, period = 2 * L / c;
    const double e0 = dynamics.energy().kinetic_mJ + stored_energy_mJ(tissue), ke0 = dynamics.energy().kinetic_mJ;
    double ke_peak = 0;
    worst_drift = 0;
    while (dynamics.time_ms() < 10 * period) {
      dynamics.step(base);
      if (dynamics.steps() % 4 == 0) {  // every point updated: the stored energy is current
        REQUIRE(tissue.rate_cycle_complete());
        worst_drift = std::max(worst_drift, std::abs(dynamics.energy().kinetic_mJ + stored_energy_mJ(tissue) - e0) / e0);
      }
      if (dynamics.time_ms() > 9 * period) ke_peak = std::max(ke_peak, dynamics.energy().kinetic_mJ);
    }
    ke_ratio = ke_peak / ke0;
  };
  double single_drift = 0, single_ke = 0, multi_drift = 0, multi_ke = 0;
  run(0, single_drift, single_ke);
  run(2, multi_drift, multi_ke);
  INFO("single rate: energy drift " << single_drift << ", kinetic peak of period 10 / initial " << single_ke);
  INFO("two rates: energy drift " << multi_drift << ", kinetic peak of period 10 / initial " << multi_ke);
  CHECK(single_drift < 2e-3);  // the stored energy is the law's: the single rate keeps the total
  CHECK(multi_drift < 1e-2);
  CHECK(std::abs(multi_ke - 1) < 0.01);
  CHECK(std::abs(multi_ke - single_ke) < 5e-3);
}

TEST_CASE("Rate levels: a pulse crosses from the fast half into the slow one at the bar speed, reflecting little",
          "[solver][dynamics][multirate][slow]") {
  // nu = 0, the 1-D bar speed. The pulse is driven at x = 0 through the fast half (x < 20) into the slow one. Both
  // runs take the same base steps, so until the pulse reaches the interface they agree; the difference of the
  // velocity at x = 10 after the pulse has passed it, before the far end's echo returns, is what the interface
  // reflected.
  struct Result {
    double speed = 0, transmitted = 0;
    std::vector<double> v10;  // the mean velocity at x = 10 after each step (units of v0)
    std::vector<double> t;
  };
  auto run = [](int max_level) {
    SpgTissue tissue(needle_test::free_box({0, 0, 0}, {40, 2, 2}, 0.5), elastic_card(0.0), SpgOptions{});
    TissueParticles& p = tissue.particles();
    const double c = std::sqrt(tissue.material().E_MPa / tissue.material().density_g_per_mm3());
    const double pulse_ms = 8.0 / c, v0 = 1e-3 * c;
    std::vector<std::int32_t> driven, at10, at30;
    for (std::int64_t i = 0; i < p.size(); ++i) {
      const double x = p.reference_mm[static_cast<size_t>(i)].x();
      if (std::abs(x) < 1e-9) driven.push_back(static_cast<std::int32_t>(i));
      if (std::abs(x - 10) < 1e-9) at10.push_back(static_cast<std::int32_t>(i));
      if (std::abs(x - 30) < 1e-9) at30.push_back(static_cast<std::int32_t>(i));
    }
    std::vector<VelocityConstraint> drive{{driven, 0, [=](double t) { return t < pulse_ms ? v0 * std::pow(std::sin(M_PI * t / pulse_ms), 2) : 0.0; }, {}}};
    TissueDynamics dynamics(tissue, drive);
    if (max_level > 0) {
      dynamics.set_rate_levels(max_level);
      dynamics.set_fast_particles(fast_below(p, 20.0));
    }
    auto mean_vx = [&](const std::vector<std::int32_t>& layer) {
      double v = 0;
      for (std::int32_t i : layer) v += p.velocity_mm_per_ms[static_cast<size_t>(i)].x();
      return v / static_cast<double>(layer.size());
    };
    const double base = tissue.stable_time_step_ms() / 4.5;
    Result r;
    double peak10 = 0, t10 = 0, peak30 = 0, t30 = 0;
    while (dynamics.time_ms() < 48.0 / c) {
      dynamics.step(base);
      const double t = dynamics.time_ms(), v10 = mean_vx(at10), v30 = mean_vx(at30);
      if (v10 > peak10) peak10 = v10, t10 = t;
      if (v30 > peak30) peak30 = v30, t30 = t;
      r.v10.push_back(v10 / v0);
      r.t.push_back(t * c);  // in mm of travel
    }
    r.speed = 20.0 / (t30 - t10) / c;
    r.transmitted = peak30 / v0;
    return r;
  };
  const Result single = run(0), multi = run(2);
  REQUIRE(single.t.size() == multi.t.size());
  // After the pulse's tail has passed x = 10 (the pulse is 8 mm long), before the far end's echo (70 mm of travel).
  double reflected = 0, tail = 0;
  for (size_t k = 0; k < single.t.size(); ++k)
    if (single.t[k] > 20.0) {
      reflected = std::max(reflected, std::abs(multi.v10[k] - single.v10[k]));
      tail = std::max(tail, std::abs(single.v10[k]));
    }
  INFO("single rate: speed / c " << single.speed << ", peak at x = 30 " << single.transmitted << " v0");
  INFO("two rates:   speed / c " << multi.speed << ", peak at x = 30 " << multi.transmitted << " v0");
  INFO("at x = 10 after the pulse: the interface's reflection " << reflected << " v0, the single rate's dispersion tail " << tail << " v0");
  CHECK(std::abs(multi.speed - single.speed) < 0.01);
  CHECK(std::abs(multi.transmitted - single.transmitted) < 0.01);
  CHECK(reflected < 0.01);
}
