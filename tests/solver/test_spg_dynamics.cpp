// Elastic dynamics of the SPG tissue: the longitudinal wave speed of a bar, energy conservation of an
// undamped vibration over ten periods, and the zero-energy mode of nodal integration that grows
// without stabilization and stays bounded with it.
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>

#include "solver/tissue/tissue_dynamics.h"
#include "tests/solver/solver_fixtures.h"

using namespace needle;

namespace {

using needle_test::elastic_card;

std::vector<std::int32_t> layer_at(const TissueParticles& p, double x) {
  std::vector<std::int32_t> layer;
  for (std::int64_t i = 0; i < p.size(); ++i)
    if (std::abs(p.reference_mm[static_cast<size_t>(i)].x() - x) < 1e-9) layer.push_back(static_cast<std::int32_t>(i));
  return layer;
}

double mean_vx(const TissueParticles& p, const std::vector<std::int32_t>& layer) {
  double v = 0;
  for (std::int32_t i : layer) v += p.velocity_mm_per_ms[static_cast<size_t>(i)].x();
  return v / static_cast<double>(layer.size());
}

}  // namespace

TEST_CASE("A longitudinal pulse travels along a bar at sqrt(E / rho)", "[solver][dynamics]") {
  // nu = 0: the 1-D bar speed sqrt(E / rho) holds in 3-D whatever the cross-section.
  const TissueMaterial card = elastic_card(0.0);
  const double c = std::sqrt(card.E_MPa / card.density_g_per_mm3());
  SpgTissue tissue(needle_test::free_box({0, 0, 0}, {40, 2, 2}, 0.5), card, SpgOptions{});
  TissueParticles& p = tissue.particles();
  const double pulse_ms = 16.0 / c, v0 = 1e-3 * c;
  std::vector<VelocityConstraint> drive{{layer_at(p, 0.0), 0,
                                         [=](double t) { return t < pulse_ms ? v0 * std::pow(std::sin(M_PI * t / pulse_ms), 2) : 0.0; }, {}}};
  TissueDynamics dynamics(tissue, drive);
  const auto station_a = layer_at(p, 10.0), station_b = layer_at(p, 30.0);
  // Time of the velocity peak at each station, refined by a parabola through the three samples around it.
  struct Peak {
    double best = -1, t = 0, prev_v = 0, prev_t = 0, prev2_v = 0, prev2_t = 0, refined = 0;
  };
  Peak a, b;
  auto track = [](Peak& pk, double v, double t) {
    if (pk.prev_v > pk.best && pk.prev_v >= v && pk.prev_v >= pk.prev2_v) {
      pk.best = pk.prev_v;
      const double y0 = pk.prev2_v, y1 = pk.prev_v, y2 = v, h = 0.5 * (t - pk.prev2_t);
      const double denom = y0 - 2 * y1 + y2;
      pk.refined = pk.prev_t + (denom != 0 ? 0.5 * h * (y0 - y2) / denom : 0.0);
    }
    pk.prev2_v = pk.prev_v, pk.prev2_t = pk.prev_t, pk.prev_v = v, pk.prev_t = t;
  };
  const double dt_cap = 0.02 * pulse_ms;  // resolve the peak in time
  while (dynamics.time_ms() < 46.0 / c) {
    dynamics.step(dt_cap);
    track(a, mean_vx(p, station_a), dynamics.time_ms());
    track(b, mean_vx(p, station_b), dynamics.time_ms());
  }
  REQUIRE(a.best > 0.5 * v0);
  REQUIRE(b.best > 0.5 * v0);
  const double measured = 20.0 / (b.refined - a.refined);
  INFO("measured " << measured << " mm/ms, expected " << c);
  CHECK(std::abs(measured / c - 1) < 0.02);
}

TEST_CASE("An undamped elastic vibration keeps its energy over ten periods", "[solver][dynamics][slow]") {
  const TissueMaterial card = elastic_card(0.3);
  const double L = 20.0, c = std::sqrt(card.E_MPa / card.density_g_per_mm3());
  SpgTissue tissue(needle_test::free_box({0, 0, 0}, {L, 2, 2}, 0.5), card, SpgOptions{});
  TissueParticles& p = tissue.particles();
  const double v0 = 1e-3 * c;  // strain amplitude ~1e-3
  for (std::int64_t i = 0; i < p.size(); ++i)
    p.velocity_mm_per_ms[static_cast<size_t>(i)].x() = v0 * std::cos(M_PI * p.reference_mm[static_cast<size_t>(i)].x() / L);
  TissueDynamics dynamics(tissue, {});
  const double ke0 = dynamics.energy().kinetic_mJ;
  const double period = 2 * L / c;
  double worst_balance = 0, ke_peak_last_period = 0;
  while (dynamics.time_ms() < 10 * period) {
    dynamics.step();
    worst_balance = std::max(worst_balance, dynamics.energy().relative_error());
    if (dynamics.time_ms() > 9 * period) ke_peak_last_period = std::max(ke_peak_last_period, dynamics.energy().kinetic_mJ);
  }
  INFO("balance error " << worst_balance << ", kinetic peak in period 10 / initial " << ke_peak_last_period / ke0);
  CHECK(worst_balance < 0.01);
  // Stored energy goes back into motion: the kinetic peak of the tenth period is the initial one.
  CHECK(std::abs(ke_peak_last_period / ke0 - 1) < 0.01);
}

TEST_CASE("The odd-even mode costs no energy under nodal integration, smoothing gives it stiffness", "[solver][dynamics]") {
  // On a regular lattice the RK gradients at a particle are odd in the neighbour offset, so the
  // odd-even pattern (-1)^(i+j+k) has exactly zero strain at every particle whose stencil is complete:
  // a zero-energy mode that nothing restores. Smoothing must push it back.
  auto interior_response = [](Stabilization s, double* defect_after_filter) {
    SpgOptions options;
    options.stabilization = s;
    SpgTissue tissue(needle_test::free_box({0, 0, 0}, {5, 5, 5}, 0.5), elastic_card(0.3), options);
    TissueParticles& p = tissue.particles();
    const double a = 1e-3;
    std::vector<Eigen::Vector3d> mode(static_cast<size_t>(p.size()));
    for (std::int64_t i = 0; i < p.size(); ++i) {
      const Eigen::Vector3d X = p.reference_mm[static_cast<size_t>(i)] / 0.5;
      const int parity = (static_cast<int>(std::lround(X.x() + X.y() + X.z())) % 2) ? -1 : 1;
      mode[static_cast<size_t>(i)] = Eigen::Vector3d(a * parity, 0, 0);
      p.position_mm[static_cast<size_t>(i)] += mode[static_cast<size_t>(i)];
    }
    tissue.compute_forces(1e-6);
    // Rayleigh quotient -f.d / |d|^2 over particles two layers or more inside (complete stencils all round).
    double work = 0, norm = 0, defect = 0;
    for (std::int64_t i = 0; i < p.size(); ++i) {
      const Eigen::Vector3d X = p.reference_mm[static_cast<size_t>(i)];
      if (!((X.array() > 0.9).all() && (X.array() < 4.1).all())) continue;
      work -= p.force_N[static_cast<size_t>(i)].dot(mode[static_cast<size_t>(i)]);
      norm += mode[static_cast<size_t>(i)].squaredNorm();
      defect = std::max(defect, p.defect_mm[static_cast<size_t>(i)]);
    }
    if (defect_after_filter) {
      for (int k = 0; k < options.smoothing_interval_steps; ++k) tissue.end_of_step();
      tissue.compute_forces(1e-6);
      double after = 0;
      for (std::int64_t i = 0; i < p.size(); ++i) {
        const Eigen::Vector3d X = p.reference_mm[static_cast<size_t>(i)];
        if ((X.array() > 0.9).all() && (X.array() < 4.1).all()) after = std::max(after, p.defect_mm[static_cast<size_t>(i)]);
      }
      *defect_after_filter = after / defect;
    }
    return work / norm;  // N/mm per unit mode amplitude
  };
  const TissueMaterial card = elastic_card(0.3);
  const double kappa = 0.1 * card.p_wave_modulus_MPa() * 0.125 / 0.25;  // penalty stiffness of one particle
  const double none = interior_response(Stabilization::none, nullptr);
  const double penalty = interior_response(Stabilization::penalty, nullptr);
  double filter_ratio = 1;
  interior_response(Stabilization::filter, &filter_ratio);
  INFO("mode stiffness: none " << none << ", penalty " << penalty << " N/mm (kappa " << kappa << "); filter leaves "
                               << filter_ratio << " of the defect");
  CHECK(std::abs(none) < 1e-12 * kappa);
  CHECK(penalty > 0.5 * kappa);
  CHECK(filter_ratio < 0.95);
}

TEST_CASE("A viscoelastic bar's vibration decays at the closed-form loss factor, and the energy balance books it", "[solver][dynamics][viscoelastic][slow]") {
  // The vibrating bar above, with a tenth of the shear stress relaxing at tau = 1 / omega, where the
  // branch's loss is largest (so the SPG bar's slightly different frequency hardly changes it). Complex
  // shear modulus G* = G (1 - g + g i w tau / (1 + i w tau)); the thin bar's modulus E* = 9 K G* / (3 K + G*);
  // its stored-plus-kinetic energy decays as exp(-eta w t), eta = Im E* / Re E*, so the kinetic peak at
  // the end of period 3 is exp(-6 pi eta) of the first.
  TissueMaterial card = elastic_card(0.3);
  const double L = 20.0;
  const double c = std::sqrt(card.E_MPa / card.density_g_per_mm3());
  const double omega = M_PI * c / L, period = 2 * M_PI / omega;
  card.relaxing_shear_fraction = 0.1;
  card.relaxation_time_ms = 1 / omega;
  const std::complex<double> i_wt(0, 1);  // i w tau
  const double G = card.shear_modulus_MPa(), K = card.bulk_modulus_MPa(), g = card.relaxing_shear_fraction;
  const std::complex<double> G_star = G * (1 - g + g * i_wt / (1.0 + i_wt));
  const std::complex<double> E_star = 9 * K * G_star / (3 * K + G_star);
  const double eta = E_star.imag() / E_star.real();
  SpgTissue tissue(needle_test::free_box({0, 0, 0}, {L, 2, 2}, 0.5), card, SpgOptions{});
  TissueParticles& p = tissue.particles();
  const double v0 = 1e-3 * c;
  for (std::int64_t i = 0; i < p.size(); ++i)
    p.velocity_mm_per_ms[static_cast<size_t>(i)].x() = v0 * std::cos(M_PI * p.reference_mm[static_cast<size_t>(i)].x() / L);
  TissueDynamics dynamics(tissue, {});
  const double ke0 = dynamics.energy().kinetic_mJ;
  double worst_balance = 0, ke_peak = 0;
  while (dynamics.time_ms() < 3.25 * period) {
    dynamics.step();
    worst_balance = std::max(worst_balance, dynamics.energy().relative_error());
    if (dynamics.time_ms() > 2.75 * period) ke_peak = std::max(ke_peak, dynamics.energy().kinetic_mJ);
  }
  const double expected = std::exp(-6 * M_PI * eta);
  INFO("eta " << eta << ", kinetic peak after 3 periods / initial " << ke_peak / ke0 << ", closed form " << expected << ", balance "
              << worst_balance);
  CHECK(expected < 0.5);  // the decay is large enough to measure
  CHECK(ke_peak / ke0 == Approx(expected).epsilon(0.05));
  CHECK(worst_balance < 0.01);  // the branch's dissipation is internal work, not drift
}
