// Tissue particle lattices: counts, volumes and boundary flags against values computed by hand.
#include <catch2/catch.hpp>

#include <cmath>

#include "core/input_error.h"
#include "mesher/particle_lattice.h"

using namespace needle;

namespace {
int count_flag(const ParticleSet& p, std::uint8_t bit) {
  int n = 0;
  for (Eigen::Index i = 0; i < p.flags.size(); ++i) n += (p.flags[i] & bit) ? 1 : 0;
  return n;
}
}  // namespace

TEST_CASE("the paper's half block at 0.4 mm: count, volume and boundary flags are exact", "[mesher][particles]") {
  const ParticleSet p = make_particle_lattice(TissueBox{}, LatticeOptions{});
  const int nx = 40 / 0.4 + 1.5, ny = 8 / 0.4 + 1.5, nz = 2 / 0.4 + 1.5;  // 101, 21, 6 nodes
  REQUIRE(p.num_particles() == nx * ny * nz);
  CHECK(p.volume_mm3.sum() == Approx(40.0 * 8.0 * 2.0).epsilon(1e-13));
  CHECK(p.volume_mm3.maxCoeff() == Approx(0.4 * 0.4 * 0.4).epsilon(1e-12));  // interior particle
  CHECK(p.volume_mm3.minCoeff() == Approx(0.4 * 0.4 * 0.4 / 8).epsilon(1e-12));  // corner particle
  // Fixed: faces y = -4, y = +4, z = 2 (inclusion-exclusion over their two shared edges).
  CHECK(count_flag(p, kParticleFixed) == 2 * nx * nz + nx * ny - 2 * nx);
  CHECK(count_flag(p, kParticleSymmetry) == nx * ny);      // z = 0
  CHECK(count_flag(p, kParticleFreeSurface) == 2 * ny * nz);  // x = 0 and x = 40
  // The needle path y = z = 0 is a row of particles.
  int on_axis = 0;
  for (int i = 0; i < p.num_particles(); ++i) on_axis += (std::abs(p.x_mm(i, 1)) < 1e-12 && std::abs(p.x_mm(i, 2)) < 1e-12);
  CHECK(on_axis == nx);
}

TEST_CASE("a refined region of interest keeps the total volume and refines what it covers", "[mesher][particles]") {
  LatticeOptions o;
  o.spacing_mm = 0.4;
  o.region_of_interest = RegionOfInterest{{-1, -1.0, 0}, {50, 1.0, 0.8}, 2};  // the needle's tube, all x
  const ParticleSet p = make_particle_lattice(TissueBox{}, o);
  // x: whole axis refined -> 201 nodes; y: [-1.2, 1.2] (snapped outward) refined -> 21 + 6; z: [0, 0.8] -> 6 + 2.
  CHECK(p.nodes_per_axis == Eigen::Vector3i(201, 27, 8));
  CHECK(p.num_particles() == 201 * 27 * 8);
  CHECK(p.volume_mm3.sum() == Approx(640.0).epsilon(1e-13));
  CHECK(p.spacing_mm.minCoeff() == Approx(0.2).epsilon(1e-12));
  CHECK(p.spacing_mm.maxCoeff() == Approx(0.4).epsilon(1e-12));
}

TEST_CASE("a spacing that does not divide the box is rounded and the volume stays exact", "[mesher][particles]") {
  LatticeOptions o;
  o.spacing_mm = 0.3;  // 40/0.3 = 133.3 -> 133 intervals; 8/0.3 -> 27; 2/0.3 -> 7
  const ParticleSet p = make_particle_lattice(TissueBox{}, o);
  CHECK(p.nodes_per_axis == Eigen::Vector3i(134, 28, 8));
  CHECK(p.volume_mm3.sum() == Approx(640.0).epsilon(1e-13));
}

TEST_CASE("bad lattice input is refused", "[mesher][particles][errors]") {
  LatticeOptions o;
  o.spacing_mm = 0;
  CHECK_THROWS_AS(make_particle_lattice(TissueBox{}, o), InputError);
  o.spacing_mm = -0.4;
  CHECK_THROWS_AS(make_particle_lattice(TissueBox{}, o), InputError);
  o.spacing_mm = 3.0;  // larger than the 2 mm depth
  CHECK_THROWS_AS(make_particle_lattice(TissueBox{}, o), InputError);
  o.spacing_mm = 0.001;  // 6e11 particles
  CHECK_THROWS_AS(make_particle_lattice(TissueBox{}, o), InputError);
  TissueBox empty;
  empty.max_mm.x() = empty.min_mm.x();
  CHECK_THROWS_AS(make_particle_lattice(empty, LatticeOptions{}), InputError);
  LatticeOptions outside;
  outside.region_of_interest = RegionOfInterest{{100, 0, 0}, {101, 1, 1}, 2};
  CHECK_THROWS_AS(make_particle_lattice(TissueBox{}, outside), InputError);
  CHECK_THROWS_AS(face_condition_from_name("clamped"), InputError);
}
