// The lip release (solver/separation/lip_release.h): which particles it cuts loose, against counts that follow from a
// lattice's layout; that it cuts exactly their bonds; and that a released particle carries no stress while the
// tissue's internal forces still sum to zero (momentum) and no mass is lost.
#include <catch2/catch.hpp>
#include <cmath>

#include "solver/separation/lip_release.h"
#include "solver/separation/separation_models.h"
#include "tests/solver/solver_fixtures.h"

using namespace needle;

namespace {

// Particles at x = 0, 0.2, ..., 2.0, y = -0.95, -0.75, ..., 0.85 and z = 0, 0.2, ..., 1.0 (none on a band's edge).
std::vector<Vec3d> lattice() {
  std::vector<Vec3d> x;
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j < 10; ++j)
      for (int k = 0; k <= 5; ++k) x.emplace_back(0.2 * i, -0.95 + 0.2 * j, 0.2 * k);
  return x;
}

// A "needle": a ring of radius 0.5 about the x axis far behind, and its most distal node, tip point A, at tip.
Eigen::MatrixX3d needle_with_tip(const Eigen::Vector3d& tip) {
  Eigen::MatrixX3d n(9, 3);
  for (int k = 0; k < 8; ++k) n.row(k) << tip.x() - 5, 0.5 * std::sin(k * M_PI / 4), 0.5 * std::cos(k * M_PI / 4);
  n.row(8) = tip.transpose();
  return n;
}

}  // namespace

TEST_CASE("The lip release takes the particles below tip point A, inside the rod's outline, within its depth and window", "[solver][lip]") {
  const std::vector<Vec3d> x = lattice();
  // A at y = -0.05: a lip 0.45 mm thick (AMB's is 0.43). Window x in [0.55, 1.05]: columns 0.6, 0.8, 1.0.
  const Eigen::MatrixX3d needle = needle_with_tip({1.05, -0.05, 0.0});
  LipReleaseOptions options;  // crushed or free select alike
  options.mode = LipReleaseMode::crushed;
  options.depth_mm = 0.45;
  const LipRelease lip(needle, options);
  CHECK(lip.rod_radius_mm() == Approx(0.5));
  CHECK(lip.lip_thickness_mm() == Approx(0.45));
  // Layers y = -0.15 (z^2 <= 0.25 - 0.0225: z = 0, 0.2, 0.4) and y = -0.35 (z^2 <= 0.1275: z = 0, 0.2); y = -0.55 is
  // below the rod. 3 columns x (3 + 2) = 15.
  const std::vector<std::int32_t> band = lip.particles_in_band(x, needle);
  CHECK(band.size() == 15);
  for (const std::int32_t i : band) {
    const Vec3d& p = x[static_cast<size_t>(i)];
    CHECK(p.x() >= 0.55);
    CHECK(p.x() <= 1.05);
    CHECK(p.y() < -0.05);
    CHECK(p.y() * p.y() + p.z() * p.z() <= 0.25);
  }

  SECTION("a shallower band takes only the lip's top") {
    options.depth_mm = 0.25;  // y in [-0.30, -0.05): the layer -0.15 only
    CHECK(LipRelease(needle, options).particles_in_band(x, needle).size() == 9);
  }
  SECTION("a deeper band takes no more than the lip: below the rod's bottom nothing is released") {
    options.depth_mm = 2.0;
    CHECK(LipRelease(needle, options).particles_in_band(x, needle).size() == 15);
    LipReleaseOptions whole;  // the band's default: the whole lip
    whole.mode = LipReleaseMode::crushed;
    CHECK(whole.whole_lip());
    CHECK(LipRelease(needle, whole).particles_in_band(x, needle).size() == 15);
    CHECK(LipRelease::lip_thickness_mm(needle) == Approx(0.45));
  }
  SECTION("a band that starts below A takes the lip's deeper part: a lip thinner than where it starts keeps everything") {
    options.below_mm = 0.25;  // y in [-1.30, -0.30): the layer -0.35 only (2 z a column)
    options.depth_mm = 1.0;
    CHECK(LipRelease(needle, options).particles_in_band(x, needle).size() == 6);
    options.below_mm = 0.45;  // the lip is 0.45 thick: nothing of it lies deeper
    CHECK(LipRelease(needle, options).particles_in_band(x, needle).empty());
  }
  SECTION("a tip point on the rod's bottom (SB) has no lip") {
    const Eigen::MatrixX3d sb = needle_with_tip({1.05, -0.5, 0.0});
    options.depth_mm = 1.0;
    const LipRelease none(sb, options);
    CHECK(none.lip_thickness_mm() == Approx(0.0));
    CHECK(none.particles_in_band(x, sb).empty());
  }
  SECTION("the band follows the needle") {
    // The whole needle 0.2 mm up: A at y = 0.15, the axis at y = 0.2. Band y in [-0.30, 0.15): layers 0.05
    // ((0.05 - 0.2)^2 = 0.0225: z = 0, 0.2, 0.4) and -0.15 (0.1225: z = 0, 0.2): 15 again, one layer up.
    Eigen::MatrixX3d moved = needle;
    moved.col(1).array() += 0.2;
    const std::vector<std::int32_t> up = lip.particles_in_band(x, moved);
    CHECK(up.size() == 15);
    for (const std::int32_t i : up) CHECK(x[static_cast<size_t>(i)].y() > -0.2);
  }
  SECTION("off, no release: the solver's default, while a scene's default crushes") {
    CHECK(LipReleaseOptions{}.mode == LipReleaseMode::off);
    CHECK(scene_separation_defaults().lip.mode == LipReleaseMode::crushed);
    options.mode = LipReleaseMode::off;
    CHECK(LipRelease(needle, options).particles_in_band(x, needle).empty());
  }
}

TEST_CASE("Released particles lose every bond and carry no stress, mass and the internal forces' zero sum are kept", "[solver][lip]") {
  // A 2 x 1.2 x 1 mm block at 0.2 mm, squeezed 10 % in y about its centre, with tip point A at (1.05, 0.05, 0).
  ParticleSet set = needle_test::free_box({0, -0.6, 0}, {2, 0.6, 1}, 0.2);
  TissueMaterial material;
  material.E_MPa = 0.1;
  material.rate_law = RateLaw::off;
  SpgTissue tissue(set, material, SpgOptions{});
  TissueParticles& p = tissue.particles();
  for (Vec3d& xi : p.position_mm) xi.y() *= 0.9;
  tissue.compute_forces(1e-4);
  double mass_before = 0;
  for (const double m : p.mass_g) mass_before += m;

  const Eigen::MatrixX3d needle = needle_with_tip({1.05, 0.05, 0.0});
  LipReleaseOptions options;
  options.depth_mm = 0.4;
  options.mode = LipReleaseMode::free;
  LipRelease lip(needle, options);
  const std::vector<std::int32_t> band = lip.particles_in_band(p.position_mm, needle);
  REQUIRE_FALSE(band.empty());
  const std::vector<std::int64_t> their_bonds = LipRelease::bonds_of(tissue.bonds(), band);
  const std::int64_t intact_before = static_cast<std::int64_t>(tissue.bonds().bonds.size()) - tissue.bonds().broken_count;
  CHECK(lip.release(tissue, needle) == static_cast<std::int64_t>(band.size()));
  CHECK(lip.bonds_cut() == static_cast<std::int64_t>(their_bonds.size()));
  CHECK(static_cast<std::int64_t>(tissue.bonds().bonds.size()) - tissue.bonds().broken_count == intact_before - lip.bonds_cut());
  for (const std::int32_t i : band) {
    INFO("particle " << i);
    CHECK_FALSE(tissue.is_integration_point(i));
    for (std::int64_t k = tissue.bonds().particle_offset[static_cast<size_t>(i)]; k < tissue.bonds().particle_offset[static_cast<size_t>(i) + 1]; ++k)
      CHECK(tissue.bonds().bonds[static_cast<size_t>(tissue.bonds().particle_bonds[static_cast<size_t>(k)])].broken);
  }
  // Released once: a second call finds nothing new.
  CHECK(lip.release(tissue, needle) == 0);

  tissue.compute_forces(1e-4);
  Vec3d total = Vec3d::Zero();
  double scale = 0;
  for (std::int64_t i = 0; i < p.size(); ++i) {
    total += p.force_N[static_cast<size_t>(i)];
    scale = std::max(scale, p.force_N[static_cast<size_t>(i)].norm());
  }
  for (const std::int32_t i : band) CHECK(p.stress_MPa[static_cast<size_t>(i)].norm() == 0.0);
  INFO("sum of internal forces " << total.transpose() << " N; largest " << scale << " N");
  REQUIRE(scale > 0);
  CHECK(total.norm() < 1e-9 * scale * static_cast<double>(p.size()));
  double mass_after = 0;
  for (const double m : p.mass_g) mass_after += m;
  CHECK(mass_after == mass_before);
}

TEST_CASE("The lip release's options refuse unphysical values with the field's name", "[solver][lip]") {
  LipReleaseOptions o;
  o.depth_mm = -0.1;
  CHECK_THROWS_WITH(o.validate("tissue.contact"), Catch::Contains("tissue.contact: depth_mm must be positive"));
  o.depth_mm = 0;
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("depth_mm must be positive"));
  o.depth_mm = std::nan("");
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("depth_mm must be positive"));
  o.depth_mm = 0.3;
  o.below_mm = -1;
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("below_mm must be zero or positive"));
}

namespace {

// A 1.2 mm cube at 0.2 mm, its particles moved by x -> F x; the stress at its centre particle after one update.
struct DeformedCube {
  SpgTissue tissue;
  std::int64_t centre = -1;
  explicit DeformedCube(const TissueMaterial& material) : tissue(needle_test::free_box({0, 0, 0}, {1.2, 1.2, 1.2}, 0.2), material, SpgOptions{}) {
    double best = 1e300;
    for (std::int64_t i = 0; i < tissue.particles().size(); ++i) {
      const double d = (tissue.particles().position_mm[static_cast<size_t>(i)] - Vec3d(0.6, 0.6, 0.6)).norm();
      if (d < best) best = d, centre = i;
    }
  }
  Mat3d stress_after(const Mat3d& F, bool crushed) {
    TissueParticles& p = tissue.particles();
    if (crushed)
      for (std::uint8_t& f : p.flags) f |= kParticleCrushed;
    tissue.compute_forces(0);
    for (std::int64_t i = 0; i < p.size(); ++i) p.position_mm[static_cast<size_t>(i)] = F * p.position_mm[static_cast<size_t>(i)];
    tissue.compute_forces(1e-3);
    return p.stress_MPa[static_cast<size_t>(centre)];
  }
};

TissueMaterial elastic_card() {
  TissueMaterial m;
  m.E_MPa = 0.1;
  m.nu = 0.45;
  m.rate_law = RateLaw::off;
  return m;
}

}  // namespace

TEST_CASE("Crushed material keeps its pressure and loses its shear: simple shear and uniform compression against the intact card",
          "[solver][lip]") {
  const TissueMaterial card = elastic_card();
  const double shear_modulus_MPa = card.E_MPa / (2 * (1 + card.nu));
  SECTION("simple shear, gamma 0.02: intact carries G gamma, crushed nothing") {
    Mat3d F = Mat3d::Identity();
    F(0, 1) = 0.02;
    const Mat3d intact = DeformedCube(card).stress_after(F, false);
    const Mat3d crushed = DeformedCube(card).stress_after(F, true);
    INFO("intact sigma_xy " << intact(0, 1) << " MPa (G gamma " << shear_modulus_MPa * 0.02 << "); crushed\n" << crushed);
    CHECK(intact(0, 1) == Approx(shear_modulus_MPa * 0.02).epsilon(0.02));
    CHECK(crushed(0, 1) == 0.0);
    CHECK((crushed - crushed.trace() / 3 * Mat3d::Identity()).norm() == 0.0);
    CHECK(std::abs(crushed.trace()) < 1e-3 * std::abs(intact(0, 1)));  // simple shear keeps the volume
  }
  SECTION("uniform compression, 2 %: the pressure is the intact card's") {
    const Mat3d F = 0.98 * Mat3d::Identity();
    const Mat3d intact = DeformedCube(card).stress_after(F, false);
    const Mat3d crushed = DeformedCube(card).stress_after(F, true);
    INFO("intact\n" << intact << "\ncrushed\n" << crushed);
    CHECK(intact.trace() < 0);
    CHECK(crushed.trace() == Approx(intact.trace()).epsilon(1e-12));
  }
}

TEST_CASE("The crushed lip keeps its bonds and its particles as integration points, flagged crushed", "[solver][lip]") {
  SpgTissue tissue(needle_test::free_box({0, -0.6, 0}, {2, 0.6, 1}, 0.2), elastic_card(), SpgOptions{});
  const Eigen::MatrixX3d needle = needle_with_tip({1.05, 0.05, 0.0});
  LipReleaseOptions options;
  options.depth_mm = 0.4;
  options.mode = LipReleaseMode::crushed;
  LipRelease lip(needle, options);
  const std::vector<std::int32_t> band = lip.particles_in_band(tissue.particles().position_mm, needle);
  REQUIRE_FALSE(band.empty());
  const std::int64_t broken_before = tissue.bonds().broken_count;
  CHECK(lip.release(tissue, needle) == static_cast<std::int64_t>(band.size()));
  CHECK(lip.bonds_cut() == 0);
  CHECK(tissue.bonds().broken_count == broken_before);
  std::int64_t crushed = 0;
  for (std::int64_t i = 0; i < tissue.particles().size(); ++i)
    if (tissue.particles().flags[static_cast<size_t>(i)] & kParticleCrushed) ++crushed;
  CHECK(crushed == static_cast<std::int64_t>(band.size()));
  for (const std::int32_t i : band) CHECK(tissue.is_integration_point(i));
  CHECK(lip_release_mode_from_name(lip_release_mode_name(LipReleaseMode::crushed)) == LipReleaseMode::crushed);
  CHECK_THROWS_WITH(lip_release_mode_from_name("dissolved"), Catch::Contains("must be crushed, free or off (got 'dissolved')"));
  for (const LipReleaseMode m : {LipReleaseMode::off, LipReleaseMode::free, LipReleaseMode::crushed})
    CHECK(lip_release_mode_from_name(lip_release_mode_name(m)) == m);
}
