// The crack the tip drives past the rod's outline (solver/separation/tip_crack.h): which bonds its fins cut, against
// counts that follow from a lattice's layout, and single bonds placed on either side of the fin's edges.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>

#include "solver/separation/tip_crack.h"

using namespace needle;

namespace {

// Particles at x = 0, 0.2, ..., 2.0, y = -0.3, -0.1, 0.1, 0.3 and z = 0, 0.2, ..., 1.0 (none on y = 0), with a
// bond between each particle and its neighbour above it (y + 0.2).
struct VerticalBonds {
  std::vector<Vec3d> x;
  BondNetwork bonds;
  int columns_x = 11, columns_z = 6;
  VerticalBonds() {
    for (int i = 0; i < columns_x; ++i)
      for (int k = 0; k < columns_z; ++k)
        for (int j = 0; j < 4; ++j) {
          if (j > 0) bonds.bonds.push_back({static_cast<std::int32_t>(x.size() - 1), static_cast<std::int32_t>(x.size())});
          x.push_back(Vec3d(0.2 * i, -0.3 + 0.2 * j, 0.2 * k));
        }
    bonds.index(static_cast<std::int64_t>(x.size()));
  }
  // Appends a bond between two new particles; returns its index.
  std::int64_t add(const Vec3d& a, const Vec3d& b) {
    x.push_back(a);
    x.push_back(b);
    bonds.bonds.push_back({static_cast<std::int32_t>(x.size() - 2), static_cast<std::int32_t>(x.size() - 1)});
    bonds.index(static_cast<std::int64_t>(x.size()));
    return static_cast<std::int64_t>(bonds.bonds.size() - 1);
  }
};

// A two-node "needle" whose most distal node, the tip point A, sits at tip.
Eigen::MatrixX3d needle_with_tip(const Eigen::Vector3d& tip) {
  Eigen::MatrixX3d n(2, 3);
  n.row(0) = (tip - Eigen::Vector3d(5, 0, 0)).transpose();
  n.row(1) = tip.transpose();
  return n;
}

}  // namespace

TEST_CASE("A horizontal fin at the tip point cuts the bonds across it within its reach and window", "[solver][crack]") {
  VerticalBonds lattice;
  const Eigen::MatrixX3d needle = needle_with_tip({1.05, 0.0, 0.0});
  TipCrackOptions options;
  options.reach_mm = 0.5;
  options.angles_deg = {0.0};
  const TipCrack crack(needle, options);
  const std::vector<std::int64_t> cut = crack.bonds_across(lattice.bonds, lattice.x, needle);
  // Only the bonds from y = -0.1 to 0.1 cross y = 0; their crossings are the columns (x, z) with x from A.x - 0.5
  // to A.x (0.6, 0.8, 1.0) and z from 0 to the reach (0, 0.2, 0.4): 9.
  CHECK(cut.size() == 9);
  for (const std::int64_t b : cut) {
    const Vec3d& p = lattice.x[static_cast<size_t>(lattice.bonds.bonds[static_cast<size_t>(b)].i)];
    CHECK(p.y() == Approx(-0.1));
    CHECK(p.x() >= 1.05 - TipCrack::kWindowBehindMm);
    CHECK(p.x() <= 1.05);
    CHECK(p.z() <= 0.5);
  }

  SECTION("a lead runs the crack ahead of the tip point") {
    options.lead_mm = 0.3;  // the window reaches x = 1.35: one more column (1.2)
    CHECK(TipCrack(needle, options).bonds_across(lattice.bonds, lattice.x, needle).size() == 12);
  }
  SECTION("a longer reach cuts further from the axis") {
    options.reach_mm = 0.9;  // z up to 0.9: five columns of z
    CHECK(TipCrack(needle, options).bonds_across(lattice.bonds, lattice.x, needle).size() == 15);
  }
  SECTION("the fin follows the tip point") {
    const Eigen::MatrixX3d raised = needle_with_tip({1.05, 0.2, 0.0});  // y = 0.2 lies between the layers 0.1 and 0.3
    const std::vector<std::int64_t> cut_raised = TipCrack(needle, options).bonds_across(lattice.bonds, lattice.x, raised);
    CHECK(cut_raised.size() == 9);
    for (const std::int64_t b : cut_raised)
      CHECK(lattice.x[static_cast<size_t>(lattice.bonds.bonds[static_cast<size_t>(b)].i)].y() == Approx(0.1));
  }
  SECTION("broken bonds are not cut again") {
    for (const std::int64_t b : cut) lattice.bonds.bonds[static_cast<size_t>(b)].broken = true;
    CHECK(crack.bonds_across(lattice.bonds, lattice.x, needle).empty());
  }
  SECTION("a fin in the mirror half or in the symmetry plane cuts nothing in a half model") {
    options.angles_deg = {180.0, 90.0, -90.0};
    const std::vector<std::int64_t> none = TipCrack(needle, options).bonds_across(lattice.bonds, lattice.x, needle);
    // 180: the crossings at z > 0 lie behind the fin's edge (r < 0); the ones at z = 0 lie on it (r = 0) and
    // are the horizontal fin's too. +-90: the plane z = 0 holds particles, never a crossing strictly between them.
    for (const std::int64_t b : none) CHECK(lattice.x[static_cast<size_t>(lattice.bonds.bonds[static_cast<size_t>(b)].i)].z() == 0.0);
    CHECK(none.size() == 3);
  }
  SECTION("no reach, no crack") {
    options.reach_mm = 0;
    CHECK(TipCrack(needle, options).bonds_across(lattice.bonds, lattice.x, needle).empty());
  }
}

TEST_CASE("A slanted fin cuts a bond by where it crosses the fin, not by where its particles are", "[solver][crack]") {
  VerticalBonds lattice;
  const Eigen::MatrixX3d needle = needle_with_tip({1.05, 0.0, 0.0});
  TipCrackOptions options;
  options.reach_mm = 0.5;
  options.angles_deg = {45.0};  // the fin is the half-plane y = z >= 0 from the axis
  // Bonds across y = z: from (0.8, 0.3, 0.1) to (0.8, 0.1, 0.3) crosses at (0.2, 0.2), r = 0.28: cut. The same
  // shifted out to cross at (0.4, 0.4), r = 0.57: beyond the reach.
  const std::int64_t inside = lattice.add(Vec3d(0.8, 0.3, 0.1), Vec3d(0.8, 0.1, 0.3));
  const std::int64_t beyond = lattice.add(Vec3d(0.8, 0.5, 0.3), Vec3d(0.8, 0.3, 0.5));
  // Both ends far apart in x: it crosses the fin's plane at x = 0.3, behind the window (from 0.55).
  const std::int64_t behind = lattice.add(Vec3d(-0.2, 0.3, 0.1), Vec3d(0.8, 0.1, 0.3));
  // The mirror fin's crossing (y = -z) is not on this fin.
  const std::int64_t mirror = lattice.add(Vec3d(0.8, -0.3, 0.1), Vec3d(0.8, -0.1, 0.3));
  const std::vector<std::int64_t> cut = TipCrack(needle, options).bonds_across(lattice.bonds, lattice.x, needle);
  CHECK(std::count(cut.begin(), cut.end(), inside) == 1);
  CHECK(std::count(cut.begin(), cut.end(), beyond) == 0);
  CHECK(std::count(cut.begin(), cut.end(), behind) == 0);
  CHECK(std::count(cut.begin(), cut.end(), mirror) == 0);
  // The lattice's vertical bonds from y = -0.1 to 0.1 at z = 0 cross the plane y = z at y = 0, z = 0: on the
  // fin's edge (r = 0), inside the window at x = 0.6, 0.8, 1.0; the one at y = 0.1 -> 0.3 and z = 0.2 crosses
  // at y = z = 0.2, r = 0.28, at the same three x. Six in all, plus the bond inside.
  CHECK(cut.size() == 7);
}

TEST_CASE("The crack's options refuse unphysical values with the field's name", "[solver][crack]") {
  TipCrackOptions o;
  o.reach_mm = -1;
  CHECK_THROWS_WITH(o.validate("tissue.contact"), Catch::Contains("tissue.contact: reach_mm must be zero (no crack) or positive"));
  o.reach_mm = 1;
  o.angles_deg = {};
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("angles_deg must name at least one fin"));
  o.angles_deg = {200};
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("angles_deg must lie in [-180, 180]"));
  o.angles_deg = {0};
  o.lead_mm = std::nan("");
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("lead_mm must be zero or positive"));
}
