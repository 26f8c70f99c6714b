// The fired cannula (solver/insertion/cannula_firing.h), its edge's cut (separation/cannula_edge_cut.h), the sample it
// takes (insertion/tissue_sample.h) and the needle's axis frame it rides on (needle/needle_axis_frame.h): a cannula fired
// through a block of free tissue without a needle cuts out a cylinder of its bore, against the lattice's own count and
// the closed form pi R^2 L; its cut conserves mass and momentum; fired past a hole wider than it, it takes nothing.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "solver/insertion/cannula_firing.h"
#include "solver/insertion/tissue_sample.h"
#include "solver/needle/needle_axis_frame.h"
#include "solver/tissue/spg_tissue.h"
#include "solver/tissue/tissue_dynamics.h"
#include "solver_fixtures.h"

using namespace needle;

namespace {

// The lattice's particles for which keep(x) holds (every per-particle field carried along).
template <class Keep>
ParticleSet kept(const ParticleSet& all, const Keep& keep) {
  std::vector<Eigen::Index> rows;
  for (Eigen::Index i = 0; i < all.x_mm.rows(); ++i)
    if (keep(Eigen::Vector3d(all.x_mm.row(i).transpose()))) rows.push_back(i);
  ParticleSet out;
  const Eigen::Index n = static_cast<Eigen::Index>(rows.size());
  out.x_mm.resize(n, 3);
  out.volume_mm3.resize(n);
  out.spacing_mm.resize(n);
  out.flags.resize(n);
  if (all.axis_spacing_mm.rows() == all.x_mm.rows()) out.axis_spacing_mm.resize(n, 3);
  for (Eigen::Index k = 0; k < n; ++k) {
    const Eigen::Index r = rows[static_cast<size_t>(k)];
    out.x_mm.row(k) = all.x_mm.row(r);
    out.volume_mm3[k] = all.volume_mm3[r];
    out.spacing_mm[k] = all.spacing_mm[r];
    out.flags[k] = all.flags[r];
    if (out.axis_spacing_mm.rows() == n) out.axis_spacing_mm.row(k) = all.axis_spacing_mm.row(r);
  }
  return out;
}

double radius(const Vec3d& p) { return std::hypot(p.y(), p.z()); }

// A tube of mid-wall radius 1.05 mm (wall 0.1 mm) fired along x through [-0.5, 3.5] at 4 m/s from t = 0. The radius
// lies between the 0.2 mm lattice's shells around the axis (r^2 = 0.04 (a^2 + b^2): 1.020 and 1.077 mm): a particle
// closer to the cut than the tissue moves while the edge passes could land on either side.
constexpr double kMidRadiusMm = 1.05;
CannulaFiring tube_through_block() {
  CannulaTube tube;
  tube.inner_radius_mm = kMidRadiusMm - 0.05;
  tube.outer_radius_mm = kMidRadiusMm + 0.05;
  tube.edge_taper_mm = 0.2;
  CannulaStroke stroke;
  stroke.start_time_ms = 0;
  stroke.start_x_mm = -0.5;
  stroke.stop_x_mm = 3.5;
  stroke.speed_mm_per_ms = 4.0;
  return CannulaFiring(tube, stroke, NeedleAxisFrame());
}

// Fires the cannula through the tissue to its stroke's end: each step the two halves with the wall's push between them
// (wall false: none), then the edge's cut. Returns the bonds the edge cut.
std::int64_t fire(CannulaFiring& firing, SpgTissue& tissue, TissueDynamics& dynamics, bool wall) {
  const Eigen::MatrixX3d no_needle(0, 3);
  std::int64_t cut = 0;
  while (dynamics.time_ms() < firing.stroke().end_time_ms() - 1e-12) {
    const double dt = dynamics.kick_and_drift(firing.stroke().end_time_ms() - dynamics.time_ms());
    if (wall) firing.push_tissue(dynamics, no_needle, dynamics.time_ms(), dt);
    dynamics.finish_step();
    cut += tissue.cut_bonds(firing.bonds_across(tissue.bonds(), tissue.particles().position_mm, no_needle, dynamics.time_ms()));
  }
  return cut;
}

// What the tube encloses at the end (no groove: every particle in its bore within its stroke).
TissueSample sample_in_stroke(const CannulaFiring& firing, const TissueParticles& p) {
  TissueSampleInput in;
  in.reference_points = firing.reference_points(p.position_mm, Eigen::MatrixX3d(0, 3));
  in.spacing_mm = p.spacing_mm;
  in.volume_mm3 = p.reference_volume_mm3;
  in.mass_g = p.mass_g;
  in.bore_radius_mm = firing.tube().mid_radius_mm();
  in.x_lo_mm = firing.stroke().start_x_mm;
  in.x_hi_mm = firing.stroke().stop_x_mm;
  return measure_tissue_sample(in);
}

}  // namespace

TEST_CASE("The cannula's edge cuts exactly the bonds whose segment meets its mid-wall cylinder behind its front", "[solver][cannula]") {
  // Against an independent test of each bond: its segment sampled finely, a crossing where the radius passes 1.05 mm
  // between two samples, at an x between the stroke's start and the front.
  const ParticleSet block = needle_test::jittered(needle_test::free_box({0, -1.6, -1.6}, {2, 1.6, 1.6}, 0.2), 0.2);
  const SpgTissue tissue(block, needle_test::elastic_card(0.3), SpgOptions{});
  const CannulaFiring firing = tube_through_block();
  const double time_ms = 0.5;  // the front at -0.5 + 4 x 0.5 = 1.5 mm
  REQUIRE(firing.stroke().front_x_mm(time_ms) == Approx(1.5));
  const std::vector<Vec3d>& x = tissue.particles().position_mm;
  const std::vector<std::int64_t> cut = firing.bonds_across(tissue.bonds(), x, Eigen::MatrixX3d(0, 3), time_ms);
  std::vector<std::int64_t> expected;
  for (size_t b = 0; b < tissue.bonds().bonds.size(); ++b) {
    const Bond& bond = tissue.bonds().bonds[b];
    const Vec3d p = x[static_cast<size_t>(bond.i)], q = x[static_cast<size_t>(bond.j)];
    constexpr int kSamples = 4000;
    bool crosses = false;
    for (int k = 0; k < kSamples && !crosses; ++k) {
      const Vec3d a = p + (q - p) * (static_cast<double>(k) / kSamples), c = p + (q - p) * (static_cast<double>(k + 1) / kSamples);
      crosses = (radius(a) - kMidRadiusMm) * (radius(c) - kMidRadiusMm) < 0 && 0.5 * (a.x() + c.x()) >= -0.5 && 0.5 * (a.x() + c.x()) <= 1.5;
    }
    if (crosses) expected.push_back(static_cast<std::int64_t>(b));
  }
  INFO(cut.size() << " bonds cut, " << expected.size() << " by sampling");
  REQUIRE(expected.size() > 100);
  CHECK(cut == expected);
}

TEST_CASE("A cannula fired through free tissue without a needle cuts out a cylinder of its bore", "[solver][cannula][slow]") {
  // A 3 mm block of 0.2 mm particles; the tube's mid-wall radius 1.05 mm. At the stroke's end no intact bond joins a
  // particle inside the cylinder to one outside it, the particles inside are those that started inside (the wall pushes
  // each to its nearer face), and their volume (the lattice's dual cells: the block's 3 mm exactly) is within 4 % of
  // pi R^2 L (the lattice's staircase around the circle at 0.2 mm).
  SpgTissue tissue(needle_test::free_box({0, -2, -2}, {3, 2, 2}, 0.2), needle_test::elastic_card(0.3), SpgOptions{});
  TissueDynamics dynamics(tissue, {});
  CannulaFiring firing = tube_through_block();
  const std::vector<Vec3d> start = tissue.particles().position_mm;
  const std::int64_t cut = fire(firing, tissue, dynamics, true);
  const TissueParticles& p = tissue.particles();
  CHECK(cut > 0);
  CHECK(firing.pushes() > 0);
  std::int64_t straddling = 0;
  for (const Bond& bond : tissue.bonds().bonds)
    if (!bond.broken && (radius(p.position_mm[static_cast<size_t>(bond.i)]) < kMidRadiusMm) != (radius(p.position_mm[static_cast<size_t>(bond.j)]) < kMidRadiusMm))
      ++straddling;
  CHECK(straddling == 0);

  const TissueSample sample = sample_in_stroke(firing, p);
  std::int64_t started_inside = 0;
  for (size_t i = 0; i < start.size(); ++i) {
    const bool inside = radius(start[i]) < kMidRadiusMm;
    started_inside += inside;
    if (static_cast<bool>(sample.captured[i]) != inside)
      UNSCOPED_INFO("particle " << i << " from r " << radius(start[i]) << " to r " << radius(p.position_mm[i]) << " mm");
    CHECK(static_cast<bool>(sample.captured[i]) == inside);
  }
  CHECK(sample.particles == started_inside);
  const double closed_form_mm3 = M_PI * kMidRadiusMm * kMidRadiusMm * 3.0;
  INFO("sample " << sample.volume_mm3 << " mm3, pi R^2 L " << closed_form_mm3 << " mm3");
  CHECK(sample.volume_mm3 == Approx(closed_form_mm3).epsilon(0.04));
  CHECK(sample.length_mm == Approx(3.0 + 0.2).margin(0.05));  // the particles' half spacings beyond the block's faces
  CHECK(sample.floor_length_mm == 0);  // no groove, no floor
  CHECK(sample.I_s_mm() == 0);
  // Every particle of the wall's band was pushed to a face: none is left inside the wall behind the front.
  for (const Vec3d& x : p.position_mm) {
    const double r = radius(x);
    CHECK_FALSE((r > kMidRadiusMm - 0.05 + 1e-9 && r < kMidRadiusMm + 0.05 - 1e-9));
  }
}

TEST_CASE("The cannula's cut conserves the tissue's mass and momentum", "[solver][cannula]") {
  // Bonds cut by the edge alone (the wall, a body outside the tissue, is left out): the particles' masses stay as they
  // were and the internal forces, whatever bonds are left, sum to zero, so the momentum of a block set moving at random
  // stays where it started.
  SpgTissue tissue(needle_test::free_box({0, -1.6, -1.6}, {3, 1.6, 1.6}, 0.2), needle_test::elastic_card(0.3), SpgOptions{});
  TissueParticles& p = tissue.particles();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (Vec3d& v : p.velocity_mm_per_ms) v = Vec3d(u(rng), u(rng), u(rng));
  TissueDynamics dynamics(tissue, {});
  auto totals = [&p](double& mass, Vec3d& momentum) {
    mass = 0;
    momentum.setZero();
    for (size_t i = 0; i < p.mass_g.size(); ++i) {
      mass += p.mass_g[i];
      momentum += p.mass_g[i] * p.velocity_mm_per_ms[i];
    }
  };
  double mass0 = 0, mass1 = 0;
  Vec3d momentum0, momentum1;
  totals(mass0, momentum0);
  CannulaFiring firing = tube_through_block();
  const std::int64_t cut = fire(firing, tissue, dynamics, false);
  totals(mass1, momentum1);
  CHECK(cut > 0);
  CHECK(mass1 == mass0);
  double scale = 0;  // the momentum's size: sum of |m v|
  for (size_t i = 0; i < p.mass_g.size(); ++i) scale += p.mass_g[i] * p.velocity_mm_per_ms[i].norm();
  INFO("momentum before " << momentum0.transpose() << ", after " << momentum1.transpose() << ", scale " << scale);
  CHECK((momentum1 - momentum0).norm() < 1e-12 * scale);
}

TEST_CASE("A cannula fired along a hole wider than it takes nothing", "[solver][cannula]") {
  // The empty groove: the block has a 1.4 mm hole around the path, the tube's outer radius is 1.1 mm. No bond is cut,
  // no particle is pushed, and the sample is empty.
  const ParticleSet block = needle_test::free_box({0, -2, -2}, {3, 2, 2}, 0.2);
  SpgTissue tissue(kept(block, [](const Eigen::Vector3d& x) { return std::hypot(x.y(), x.z()) > 1.4; }), needle_test::elastic_card(0.3),
                   SpgOptions{});
  TissueDynamics dynamics(tissue, {});
  CannulaFiring firing = tube_through_block();
  CHECK(fire(firing, tissue, dynamics, true) == 0);
  CHECK(firing.pushes() == 0);
  const TissueParticles& p = tissue.particles();
  const TissueSample sample = sample_in_stroke(firing, p);
  CHECK(sample.particles == 0);
  CHECK(sample.volume_mm3 == 0);
  CHECK(sample.length_mm == 0);
}

TEST_CASE("The sample's lengths: the extent of the captured tissue, and I_s the floor its nearest layer covers, gaps left out", "[solver][cannula]") {
  // Five particles of 0.2 mm at x = 0, 0.2, 1.0, 1.2, 3.0 (mm), one beyond the bore, one below the floor; the floor
  // (y = -0.07) touched by those at 0.2, 1.0 and 1.2 by the contact's list, and by geometry (centre within the skin
  // 0.02 and a quarter spacing, 0.05, of it: y <= 0) the ones at 0 and 1.0, which sit at y = -0.05.
  TissueSampleInput in;
  in.reference_points = {{0, -0.05, 0}, {0.2, 0.1, 0}, {1.0, -0.05, 0}, {1.2, 0.1, 0}, {3.0, 0.1, 0}, {2.0, 0.7, 0}, {2.0, -0.3, 0}};
  in.spacing_mm.assign(7, 0.2);
  in.volume_mm3.assign(7, 0.008);
  in.mass_g.assign(7, 0.001);
  in.touches_floor = {0, 1, 1, 1, 0, 1, 1};
  in.bore_radius_mm = 0.6;
  in.x_lo_mm = -1;
  in.x_hi_mm = 3.05;
  in.floor_y_mm = -0.07;
  const TissueSample s = measure_tissue_sample(in);
  CHECK(s.particles == 5);
  CHECK(s.floor_particles == 3);
  CHECK(s.length_mm == Approx(3.05 - (-0.1)));  // clipped at x_hi
  CHECK(s.floor_length_mm == Approx(1.3 - 0.1));
  CHECK(s.floor_covered_mm == Approx(0.2 + 0.4));  // [0.1, 0.3] and [0.9, 1.3]
  CHECK(s.volume_mm3 == Approx(5 * 0.008));
  CHECK(s.mass_g == Approx(5 * 0.001));
  CHECK(s.back_x_mm == Approx(-0.1));
  CHECK(s.floor_layer_particles == 2);
  CHECK(s.floor_layer_length_mm == Approx(1.1 - (-0.1)));
  CHECK(s.floor_layer_covered_mm == Approx(0.2 + 0.2));
  CHECK(s.I_s_mm() == Approx(0.2 + 0.2));  // I_s: the floor the layer covers, not its extent nor the contact's
}

TEST_CASE("The needle's axis frame carries a point beside a translated and bent needle back to its place", "[solver][cannula]") {
  // Nodes along a rod of radius 0.5, 10 mm long; moved by a translation (exactly back) and by a bend
  // u_y = 0.01 X^2 (back to within the bend's change over half a slab and the rod's section).
  Eigen::MatrixX3d X(0, 3);
  std::vector<Eigen::Vector3d> nodes;
  for (int i = 0; i <= 100; ++i)
    for (int k = 0; k < 8; ++k) {
      const double a = 2 * M_PI * k / 8;
      nodes.emplace_back(-10 + 0.1 * i, 0.5 * std::cos(a), 0.5 * std::sin(a));
    }
  X.resize(static_cast<Eigen::Index>(nodes.size()), 3);
  for (size_t n = 0; n < nodes.size(); ++n) X.row(static_cast<Eigen::Index>(n)) = nodes[n].transpose();
  NeedleAxisFrame frame(X);
  const Eigen::Vector3d shift(30.0, 0.2, -0.1);
  frame.update(X.rowwise() + shift.transpose());
  const Eigen::Vector3d beside(-4.2, 0.6, 0.1);
  CHECK((frame.to_reference(beside + shift) - beside).norm() < 1e-12);
  Eigen::MatrixX3d bent = X;
  for (Eigen::Index n = 0; n < X.rows(); ++n) bent(n, 1) += 0.01 * X(n, 0) * X(n, 0);
  bent.col(0).array() += 30.0;
  frame.update(bent);
  const Eigen::Vector3d moved = beside + Eigen::Vector3d(30.0, 0.01 * beside.x() * beside.x(), 0);
  INFO((frame.to_reference(moved) - beside).transpose());
  CHECK((frame.to_reference(moved) - beside).norm() < 0.01);
  CHECK(NeedleAxisFrame().to_reference(beside) == beside);  // no needle: the world's frame
}
