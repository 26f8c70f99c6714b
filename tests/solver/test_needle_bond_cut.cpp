// The needle cuts the bonds its body passes through (solver/separation/needle_bond_cut.h): segment crossings of a
// meshed rod against the cylinder's closed form, on the full and on the half model, and the bonds of a
// particle lattice the rod lies in against an independent point-sampling of the cylinder.
#include <catch2/catch.hpp>
#include <cmath>

#include "mesher/needle_mesher.h"
#include "mesher/particle_lattice.h"
#include "solver/separation/needle_bond_cut.h"
#include "solver/tissue/spg_tissue.h"

using namespace needle;

namespace {

constexpr double kRadius = 0.5, kLength = 4.0;  // plain rod: x in [-4, 0], axis y = z = 0

TetMesh rod_mesh(bool half) {
  NeedleMeshOptions o;
  o.order = 1;
  o.size_mm = 0.2;
  o.high_order_optimize = false;
  return mesh_needle(plain_rod_tip(2 * kRadius, kLength), half, o);
}

Eigen::MatrixX3d positions(const TetMesh& mesh) { return mesh.X; }

// Depth of a point inside the exact cylinder (> 0 inside).
double depth_in_rod(const Eigen::Vector3d& p) {
  return std::min({kRadius - std::hypot(p.y(), p.z()), p.x() + kLength, -p.x()});
}

}  // namespace

TEST_CASE("A segment across the rod meets its surface where the cylinder says", "[solver][bond_cut][gmsh][slow]") {
  for (bool half : {false, true}) {
    const TetMesh mesh = rod_mesh(half);
    const ContactSurface surface(mesh);
    const NeedleBondCut cut(surface);
    const Eigen::MatrixX3d x = positions(mesh);
    // The faceted surface lies within the chord's sag of the cylinder: 0.2 mm edges on r 0.5.
    const double sag = kRadius * (1 - std::cos(0.2 / kRadius / 2)) + 1e-6;
    INFO((half ? "half" : "full") << " model");
    for (double z : {0.0, 0.1, 0.3}) {
      // Vertical segment from y = +0.8 to -0.8 at x = -2: enters and leaves at y = +-sqrt(r^2 - z^2).
      const Eigen::Vector3d a(-2.0, 0.8, z), b(-2.0, -0.8, z);
      const std::vector<double> s = cut.surface_crossings(a, b, x);
      INFO("z = " << z);
      REQUIRE(s.size() == 2);
      const double y = std::sqrt(kRadius * kRadius - z * z);
      CHECK(std::abs(s[0] - (0.8 - y) / 1.6) * 1.6 <= 2 * sag);
      CHECK(std::abs(s[1] - (0.8 + y) / 1.6) * 1.6 <= 2 * sag);
    }
    // Beside the rod, inside it, and along it: no crossing, one, and the end face's.
    CHECK(cut.surface_crossings({-2.0, 0.8, 0.0}, {-2.0, 0.6, 0.0}, x).empty());
    CHECK(cut.surface_crossings({-2.0, 0.0, 0.0}, {-2.0, 0.8, 0.0}, x).size() == 1);
    CHECK(cut.surface_crossings({-1.0, 0.0, 0.1}, {0.5, 0.0, 0.1}, x).size() == 1);
  }
}

TEST_CASE("The bonds through the rod are those whose segment dips into the cylinder", "[solver][bond_cut][gmsh][slow]") {
  // A lattice through which the rod is pushed (its particles inside the rod removed, as a cut leaves
  // them): a bond is cut where its segment passes through the cylinder, checked by sampling each segment
  // against the closed form. Within the faceting's sag of the surface both answers are allowed.
  const TetMesh mesh = rod_mesh(true);
  const ContactSurface surface(mesh);
  const NeedleBondCut cut(surface);
  TissueBox box;
  box.min_mm = {-3.0, -1.2, 0.0};
  box.max_mm = {-1.0, 1.2, 1.2};
  box.faces.fill(FaceCondition::free);
  box.faces[4] = FaceCondition::symmetry;
  LatticeOptions lattice;
  lattice.spacing_mm = 0.2;
  ParticleSet all = make_particle_lattice(box, lattice);
  // Keep the particles outside the rod, shifted a little so that none sits on its surface.
  std::vector<Eigen::Index> keep;
  for (Eigen::Index i = 0; i < all.x_mm.rows(); ++i) {
    all.x_mm(i, 0) += 0.013;
    all.x_mm(i, 1) += 0.021;
    if (depth_in_rod(all.x_mm.row(i).transpose()) < -0.05) keep.push_back(i);
  }
  ParticleSet outside;
  outside.x_mm.resize(static_cast<Eigen::Index>(keep.size()), 3);
  outside.volume_mm3.resize(static_cast<Eigen::Index>(keep.size()));
  outside.spacing_mm.resize(static_cast<Eigen::Index>(keep.size()));
  outside.flags.resize(static_cast<Eigen::Index>(keep.size()));
  for (size_t k = 0; k < keep.size(); ++k) {
    const Eigen::Index r = static_cast<Eigen::Index>(k);
    outside.x_mm.row(r) = all.x_mm.row(keep[k]);
    outside.volume_mm3[r] = all.volume_mm3[keep[k]];
    outside.spacing_mm[r] = all.spacing_mm[keep[k]];
    outside.flags[r] = all.flags[keep[k]];
  }
  SpgOptions spg;
  spg.dilation = 4.0;  // supports of 0.8 mm: bonds long enough to cut across the rod's section near its surface
  const SpgTissue tissue(outside, TissueMaterial{}, spg);
  const std::vector<std::int64_t> through = cut.bonds_through_needle(tissue.bonds(), tissue.particles().position_mm, mesh.X);
  REQUIRE(!through.empty());

  const double sag = kRadius * (1 - std::cos(0.2 / kRadius / 2)) + 1e-6;
  std::vector<std::uint8_t> is_cut(tissue.bonds().bonds.size(), 0);
  for (std::int64_t b : through) is_cut[static_cast<size_t>(b)] = 1;
  int expected = 0, mismatched = 0;
  for (size_t b = 0; b < tissue.bonds().bonds.size(); ++b) {
    const Bond& bond = tissue.bonds().bonds[b];
    const Vec3d& p = tissue.particles().position_mm[static_cast<size_t>(bond.i)];
    const Vec3d& q = tissue.particles().position_mm[static_cast<size_t>(bond.j)];
    double deepest = -1e9;
    for (int k = 0; k <= 400; ++k) {
      Eigen::Vector3d sample = p + (q - p) * (k / 400.0);
      sample.z() = std::abs(sample.z());  // the half model's mirror image closes the rod
      deepest = std::max(deepest, depth_in_rod(sample));
    }
    if (deepest > sag) {
      ++expected;
      if (!is_cut[b]) ++mismatched;
    } else if (deepest < -sag && is_cut[b]) {
      ++mismatched;
    }
  }
  INFO(through.size() << " bonds cut, " << expected << " clearly through the cylinder");
  CHECK(expected > 20);
  CHECK(mismatched == 0);
}

namespace {

// A particle block ahead of the rod's tip (0.2 mm lattice, supports of 0.8 mm), the particles off the rod's axis plane.
SpgTissue block_ahead_of_rod() {
  TissueBox box;
  box.min_mm = {0.1, -1.2, 0.0};
  box.max_mm = {2.5, 1.2, 1.2};
  box.faces.fill(FaceCondition::free);
  box.faces[4] = FaceCondition::symmetry;
  LatticeOptions lattice;
  lattice.spacing_mm = 0.2;
  ParticleSet particles = make_particle_lattice(box, lattice);
  for (Eigen::Index i = 0; i < particles.x_mm.rows(); ++i) particles.x_mm(i, 1) += 0.021;  // none on the rod's axis plane
  SpgOptions spg;
  spg.dilation = 4.0;
  return SpgTissue(particles, TissueMaterial{}, spg);
}

// Steps the rod (needle_at(step): its nodes' positions) through the block while the particles wander by up to
// wander_mm along each axis a step (a seeded sequence, and a jump of jump_mm at jump_step). Each step the certified
// search, the tracked search without certificates and the full scan must find the same list; the bonds found are
// then broken, as a run breaks them. Returns the bonds cut.
template <class NeedleAt>
std::int64_t cut_alongside(NeedleBondCut& certified, int steps, const NeedleAt& needle_at, double wander_mm, int jump_step = -1,
                           double jump_mm = 0) {
  const TetMesh mesh = rod_mesh(true);
  const ContactSurface& surface = certified.surface();
  NeedleBondCut uncertified(surface, NeedleBondCut::kCandidateMarginMm, false), full(surface, 0.0);
  const SpgTissue tissue = block_ahead_of_rod();
  BondNetwork bonds = tissue.bonds();
  std::vector<Vec3d> x = tissue.particles().position_mm;
  std::uint64_t state = 12345;
  const auto wander = [&state](double amplitude) {  // in [-amplitude, amplitude]
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return (static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5) * 2 * amplitude;
  };
  std::int64_t cut = 0;
  for (int step = 1; step <= steps; ++step) {
    const Eigen::MatrixX3d needle_x = needle_at(step);
    for (Vec3d& p : x)
      for (int k = 0; k < 3; ++k) p[k] += wander(step == jump_step ? jump_mm : wander_mm);
    const std::vector<std::int64_t> a = certified.bonds_through_needle_tracked(bonds, x, needle_x);
    const std::vector<std::int64_t> b = uncertified.bonds_through_needle_tracked(bonds, x, needle_x);
    const std::vector<std::int64_t> c = full.bonds_through_needle_tracked(bonds, x, needle_x);
    INFO("step " << step);
    REQUIRE(a == c);
    REQUIRE(b == c);
    CHECK(c == full.bonds_through_needle(bonds, x, needle_x));
    for (std::int64_t bond : a) bonds.mark_broken(bond);
    cut += static_cast<std::int64_t>(a.size());
  }
  return cut;
}

}  // namespace

TEST_CASE("The candidate list cuts the same bonds, in the same order, as a scan of every intact bond", "[solver][bond_cut][gmsh][slow]") {
  // The rod pushed 2 mm into the block, 0.04 mm a step, while the particles wander up to 0.006 mm a step.
  const TetMesh mesh = rod_mesh(true);
  const ContactSurface surface(mesh);
  NeedleBondCut tracked(surface);
  const int steps = 50;
  const std::int64_t cut = cut_alongside(
      tracked, steps,
      [&mesh](int step) {
        Eigen::MatrixX3d needle_x = mesh.X;
        needle_x.col(0).array() += 0.04 * step;
        return needle_x;
      },
      0.006);
  INFO(cut << " bonds cut; candidate lists made " << tracked.candidate_lists_made() << " times, the last of " << tracked.candidates()
            << " pairs");
  CHECK(cut > 100);
  // The list is made again only now and then (the tip's advance of 0.2 mm crosses half the margin every 5 steps).
  CHECK(tracked.candidate_lists_made() >= 2);
  CHECK(tracked.candidate_lists_made() <= steps / 3);
  CHECK(tracked.candidates() < block_ahead_of_rod().bonds().intact.size());
}

TEST_CASE("A bond's certificate skips its test only while nothing can have reached it", "[solver][bond_cut][gmsh][slow]") {
  // The rod starts 1 mm into the block and creeps on (0.005 mm a step along its axis, bending up by up to 0.02 mm at its
  // tip), the particles barely move (0.0005 mm a step): most tests are skipped on their certificates. Then, once, the
  // rod jumps 0.12 mm sideways, and later the particles jump by up to 0.08 mm: the bonds it then cuts had certificates,
  // which must not hold across the jump (a search that ignored the needle's or the particles' motion would miss them).
  const TetMesh mesh = rod_mesh(true);
  const ContactSurface surface(mesh);
  const int steps = 60, sideways_step = 25, particles_jump_step = 45;
  const auto needle_at = [&mesh](int step) {
    Eigen::MatrixX3d needle_x = mesh.X;
    const double tip_x = 1.0 + 0.005 * step;
    needle_x.col(0).array() += tip_x;
    for (Eigen::Index n = 0; n < needle_x.rows(); ++n) {
      const double from_base = (mesh.X(n, 0) + kLength) / kLength;  // 0 at the base, 1 at the tip
      needle_x(n, 1) += 0.02 * step / steps * from_base * from_base + (step >= sideways_step ? 0.12 : 0.0);
    }
    return needle_x;
  };
  NeedleBondCut certified(surface);
  std::int64_t cut_before_jump = 0;
  {
    NeedleBondCut probe(surface);
    cut_before_jump = cut_alongside(probe, sideways_step - 1, needle_at, 0.0005);
  }
  const std::int64_t cut = cut_alongside(certified, steps, needle_at, 0.0005, particles_jump_step, 0.08);
  INFO(cut << " bonds cut (" << cut_before_jump << " before the sideways jump); tests made " << certified.tests_made() << ", skipped "
            << certified.tests_skipped());
  CHECK(cut > cut_before_jump + 50);                           // the jump cuts bonds that were certified a step before
  CHECK(certified.tests_skipped() > certified.tests_made());  // the certificates do their work
}

TEST_CASE("A bond certified by a triangle's plane is tested again before the needle can have crossed that plane",
          "[solver][bond_cut][gmsh][slow]") {
  // The rod rests 1 mm into the block and drifts sideways into it, 0.004 mm a step (less than the smallest box the
  // certificates look within, 0.01 mm), the particles nearly still: the bonds lying along its side are certified by
  // its facets' planes, each for as long as the drift cannot have closed its distance, and are cut as the rod reaches
  // them. A certificate that ignored the motion along the facet's normal would skip them.
  const TetMesh mesh = rod_mesh(true);
  const ContactSurface surface(mesh);
  const int steps = 40;
  NeedleBondCut certified(surface);
  const std::int64_t cut = cut_alongside(
      certified, steps,
      [&mesh](int step) {
        Eigen::MatrixX3d needle_x = mesh.X;
        needle_x.col(0).array() += 1.0 + 0.0005 * step;
        needle_x.col(1).array() += 0.004 * step;
        return needle_x;
      },
      0.0002);
  INFO(cut << " bonds cut; tests made " << certified.tests_made() << ", skipped " << certified.tests_skipped());
  CHECK(cut > 100);
  CHECK(certified.tests_skipped() > certified.tests_made());
}
