// Tissue particle lattices: counts, volumes and boundary flags against values computed by hand; a nested region
// against the tensor lattice it is cut from.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

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

TEST_CASE("a nested region of interest: fine inside, coarse along every axis outside, the volume exact", "[mesher][particles]") {
  // The run's band: all x, |y| <= 1.2, 0 <= z <= 1.2, at 0.4 mm refined twice.
  LatticeOptions o;
  o.spacing_mm = 0.4;
  o.region_of_interest = RegionOfInterest{{0, -1.2, 0}, {40, 1.2, 1.2}, 2, LatticeGrading::nested};
  const ParticleSet nested = make_particle_lattice(TissueBox{}, o);
  o.region_of_interest->grading = LatticeGrading::tensor;
  const ParticleSet tensor = make_particle_lattice(TissueBox{}, o);
  // Fine block 201 x 13 x 7; the coarse lattice 101 x 21 x 6 less its nodes on the band's closed box, 101 x 7 x 4.
  CHECK(nested.num_particles() == 201 * 13 * 7 + 101 * 21 * 6 - 101 * 7 * 4);
  CHECK(tensor.num_particles() == 201 * 27 * 9);
  CHECK(nested.volume_mm3.sum() == Approx(640.0).epsilon(1e-13));
  CHECK(nested.volume_mm3.minCoeff() > 0);
  // Inside the band the particles are the tensor lattice's, with its volumes but on the band's faces.
  const auto in_band = [](const Eigen::RowVector3d& x) { return std::abs(x.y()) <= 1.2 + 1e-9 && x.z() <= 1.2 + 1e-9; };
  std::vector<std::array<double, 3>> a, b;
  for (Eigen::Index i = 0; i < nested.num_particles(); ++i)
    if (in_band(nested.x_mm.row(i))) a.push_back({nested.x_mm(i, 0), nested.x_mm(i, 1), nested.x_mm(i, 2)});
  for (Eigen::Index i = 0; i < tensor.num_particles(); ++i)
    if (in_band(tensor.x_mm.row(i))) b.push_back({tensor.x_mm(i, 0), tensor.x_mm(i, 1), tensor.x_mm(i, 2)});
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  CHECK(a == b);
  // Outside the band every particle is a coarse node with 0.4 mm along every axis; no two particles coincide.
  double outside_min_spacing = 1;
  std::vector<std::array<double, 3>> all;
  for (Eigen::Index i = 0; i < nested.num_particles(); ++i) {
    if (!in_band(nested.x_mm.row(i))) outside_min_spacing = std::min(outside_min_spacing, nested.axis_spacing_mm.row(i).minCoeff());
    all.push_back({nested.x_mm(i, 0), nested.x_mm(i, 1), nested.x_mm(i, 2)});
  }
  CHECK(outside_min_spacing == Approx(0.4).epsilon(1e-12));
  std::sort(all.begin(), all.end());
  CHECK(std::adjacent_find(all.begin(), all.end()) == all.end());
  // The faces' flags as on the tensor lattice: as many fixed particles as there are on those faces.
  const int nx = 101, ny = 21, nz = 6;  // the coarse lattice; the band reaches the faces x = 0, 40 and z = 0 only
  CHECK(count_flag(nested, kParticleFixed) == 2 * nx * nz + nx * ny - 2 * nx);
  CHECK(count_flag(nested, kParticleSymmetry) == 201 * 13 + (nx * ny - nx * 7));
  CHECK(count_flag(nested, kParticleFreeSurface) == 2 * (13 * 7 + ny * nz - 7 * 4));
  CHECK(lattice_grading_from_name("nested") == LatticeGrading::nested);
  CHECK_THROWS_AS(lattice_grading_from_name("octree"), InputError);
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
