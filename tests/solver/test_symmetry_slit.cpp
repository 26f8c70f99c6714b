// The slit in the symmetry plane (solver/separation/symmetry_slit.h): which particles it opens, and what an opened
// plane does in the dynamics: it holds z >= 0 against a block pressed onto it, and lets go of a block
// pulled off it, which then flies free as Newton's second law says.
#include <catch2/catch.hpp>
#include <cmath>

#include "solver/tissue/tissue_dynamics.h"
#include "solver/separation/symmetry_slit.h"
#include "tests/solver/solver_fixtures.h"

using namespace needle;

namespace {

// A 2 x 2 x 1 mm block on the symmetry plane z = 0, other faces free, 0.25 mm particles.
ParticleSet block_on_plane() {
  TissueBox box;
  box.min_mm = {0, 0, 0};
  box.max_mm = {2, 2, 1};
  box.faces.fill(FaceCondition::free);
  box.faces[4] = FaceCondition::symmetry;
  LatticeOptions lattice;
  lattice.spacing_mm = 0.25;
  return make_particle_lattice(box, lattice);
}

TissueMaterial soft_card() {
  TissueMaterial m;
  m.E_MPa = 0.1;
  m.rate_law = RateLaw::off;
  return m;
}

void open_whole_plane(TissueParticles& p) {
  for (std::int64_t i = 0; i < p.size(); ++i)
    if (p.flags[static_cast<size_t>(i)] & kParticleSymmetry) p.flags[static_cast<size_t>(i)] |= kParticleOpenSymmetry;
}

double centre_of_mass_z(const TissueParticles& p) {
  double m = 0, mz = 0;
  for (std::int64_t i = 0; i < p.size(); ++i) {
    m += p.mass_g[static_cast<size_t>(i)];
    mz += p.mass_g[static_cast<size_t>(i)] * p.position_mm[static_cast<size_t>(i)].z();
  }
  return mz / m;
}

double lowest_z(const TissueParticles& p) {
  double z = 1e300;
  for (const Vec3d& x : p.position_mm) z = std::min(z, x.z());
  return z;
}

}  // namespace

TEST_CASE("The slit opens the symmetry particles behind the tip within its half height of the rod's axis", "[solver][slit]") {
  // Lattice 0..4 x -2..2 x 0..1 at 0.5 mm; the needle's tip node is its most distal one.
  TissueBox box;
  box.min_mm = {0, -2, 0};
  box.max_mm = {4, 2, 1};
  box.faces.fill(FaceCondition::free);
  box.faces[2] = FaceCondition::fixed;  // y = -2: fixed particles never open
  box.faces[4] = FaceCondition::symmetry;
  LatticeOptions lattice;
  lattice.spacing_mm = 0.5;
  SpgTissue tissue(make_particle_lattice(box, lattice), soft_card(), SpgOptions{});
  TissueParticles& p = tissue.particles();

  Eigen::MatrixX3d needle_reference(3, 3);
  needle_reference << -5, 0, 0,  //
      0, -0.4, 0,                // the tip point A (most distal), 0.4 mm below the rod's axis
      -2, 0.5, 0;
  SymmetrySlitOptions options;
  options.half_height_mm = 0.65;
  SymmetrySlit slit(needle_reference, options);
  // The needle moved 2.2 mm in and 0.1 mm up: A at x = 2.2, the rod's axis at y = 0.1.
  Eigen::MatrixX3d at = needle_reference;
  at.col(0).array() += 2.2;
  at.col(1).array() += 0.1;
  // x in {0, 0.5, ..., 2} (5 columns) and y in [-0.55, 0.75]: {-0.5, 0, 0.5} (3 rows).
  CHECK(slit.open(p, at) == 5 * 3);
  // Further in, the axis down at y = -1.5: x up to 3.5 (8 columns), y in [-2.15, -0.85]: {-1.5, -1} (y = -2 is fixed).
  at = needle_reference;
  at.col(0).array() += 3.6;
  at.col(1).array() += -1.5;
  CHECK(slit.open(p, at) == 8 * 2);
  CHECK(slit.opened() == 15 + 16);
  std::int64_t open = 0, open_off_plane = 0;
  for (std::int64_t i = 0; i < p.size(); ++i) {
    const std::uint8_t f = p.flags[static_cast<size_t>(i)];
    if (f & kParticleOpenSymmetry) ++open;
    if ((f & kParticleOpenSymmetry) && !(f & kParticleSymmetry)) ++open_off_plane;
  }
  CHECK(open == 31);
  CHECK(open_off_plane == 0);
  CHECK(SymmetrySlit::opening(tissue).max_mm == 0.0);  // nothing has moved yet
  CHECK(SymmetrySlit::opening(tissue).mean_mm == 0.0);

  // A slit whose front runs 0.5 mm ahead of the tip opens the next column (x = 4) of the same band too.
  SymmetrySlitOptions leading = options;
  leading.lead_mm = 0.5;
  SymmetrySlit ahead(needle_reference, leading);
  CHECK(ahead.open(p, at) == 2);  // the band's 8 columns behind are open already

  SymmetrySlitOptions bad;
  bad.half_height_mm = -0.1;
  CHECK_THROWS_WITH(bad.validate(), Catch::Contains("half_height_mm must be zero (no slit) or positive"));
  bad.half_height_mm = 0.5;
  bad.lead_mm = -1;
  CHECK_THROWS_WITH(bad.validate(), Catch::Contains("lead_mm must be zero or positive"));
}

TEST_CASE("An opened symmetry plane holds a block pressed onto it and lets go of one pulled off it", "[solver][slit][dynamics]") {
  const double g = 5.0;  // mm/ms^2: rho g h / E = 0.05, a small static strain
  SECTION("pressed: no particle crosses the plane, and the energy balances with the plane's reaction") {
    SpgTissue tissue(block_on_plane(), soft_card(), SpgOptions{});
    open_whole_plane(tissue.particles());
    TissueDynamics dynamics(tissue, {}, Eigen::Vector3d(0, 0, -g));
    double deepest = 0, worst_balance = 0;
    while (dynamics.time_ms() < 2.0) {
      dynamics.step();
      deepest = std::min(deepest, lowest_z(tissue.particles()));
      worst_balance = std::max(worst_balance, dynamics.energy().relative_error());
    }
    INFO("lowest z " << deepest << " mm, balance " << worst_balance << ", centre of mass z " << centre_of_mass_z(tissue.particles()));
    CHECK(deepest > -1e-12);
    CHECK(worst_balance < 0.02);
    // The block came to lean on the plane: its centre sank less than a tenth of its half thickness (free fall: 10 mm).
    CHECK(centre_of_mass_z(tissue.particles()) > 0.45);
  }
  SECTION("dropped: the block lands on the plane; the impact loses kinetic energy, booked as the plane's work") {
    SpgTissue tissue(block_on_plane(), soft_card(), SpgOptions{});
    TissueParticles& p = tissue.particles();
    open_whole_plane(p);
    for (std::int64_t i = 0; i < p.size(); ++i) {
      p.position_mm[static_cast<size_t>(i)].z() += 0.02;  // a rigid lift: no strain
      p.velocity_mm_per_ms[static_cast<size_t>(i)].z() = -1.0;
    }
    TissueDynamics dynamics(tissue, {});
    const double ke0 = dynamics.energy().kinetic_mJ;
    double deepest = 1, worst_balance = 0;
    while (dynamics.time_ms() < 1.0) {
      dynamics.step();
      deepest = std::min(deepest, lowest_z(p));
      worst_balance = std::max(worst_balance, dynamics.energy().relative_error());
    }
    const EnergyBalance& e = dynamics.energy();
    INFO("lowest z " << deepest << " mm, balance " << worst_balance << ", kinetic " << e.kinetic_mJ << " of " << ke0 << " mJ, stored "
                     << -e.model_work_mJ << " mJ, plane's work " << e.constraint_work_mJ << " mJ");
    CHECK(deepest > -1e-12);
    CHECK(e.constraint_work_mJ < 0);  // the plane only takes energy out
    CHECK(worst_balance < 0.02);
  }
  SECTION("pulled: the open block falls away freely, z_cm = z0 + g t^2 / 2; a closed plane holds it") {
    auto lift = [&](bool open) {
      SpgTissue tissue(block_on_plane(), soft_card(), SpgOptions{});
      if (open) open_whole_plane(tissue.particles());
      const double z0 = centre_of_mass_z(tissue.particles());
      TissueDynamics dynamics(tissue, {}, Eigen::Vector3d(0, 0, g));
      while (dynamics.time_ms() < 0.4) dynamics.step(0.01);  // about one period of the block's lowest mode (4 h / c)
      return std::pair{centre_of_mass_z(tissue.particles()) - z0, dynamics.time_ms()};
    };
    const auto [open_rise, t_open] = lift(true);
    const auto [closed_rise, t_closed] = lift(false);
    const double free_flight = 0.5 * g * t_open * t_open;
    INFO("open: centre rose " << open_rise << " mm in " << t_open << " ms (free flight " << free_flight << "); closed: " << closed_rise);
    CHECK(open_rise == Approx(free_flight).epsilon(1e-6));
    CHECK(closed_rise < 0.5 * free_flight);
  }
}
