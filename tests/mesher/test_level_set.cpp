// The OpenVDB needle level set against brute-force point-to-triangle distances and the ideal solid.
#include <catch2/catch.hpp>

#include <random>

#include "geometry/cad_solid.h"
#include "core/input_error.h"
#include "mesher/needle_level_set.h"
#include "mesher/particle_lattice.h"
#include "mesher/triangle_distance.h"

using namespace needle;

namespace {

double brute_force_distance(const TriSurface& s, const Eigen::Vector3d& p) { return distance_to_surface_mm(s, p); }

}  // namespace

TEST_CASE("level-set distance and sign match brute force near the LMB tip", "[mesher][levelset][slow]") {
  const CadSolid solid = build_cad_solid(preset_recipe("LMB"), false);
  LevelSetOptions options;
  options.voxel_mm = 0.01;
  options.half_width_voxels = 3;
  const NeedleLevelSet level_set(solid.surface, options);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> x(-3.5, 0.3), yz(-0.56, 0.56);
  int in_band = 0, signs_checked = 0;
  double worst = 0, sum = 0;
  for (int k = 0; k < 4000 && in_band < 200; ++k) {
    const Eigen::Vector3d p(x(random), yz(random), yz(random));
    const double exact = brute_force_distance(solid.surface, p);
    if (exact > 0.5 * level_set.band_mm()) continue;  // keep points well inside the band
    const double sdf = level_set.signed_distance_mm(p);
    const bool inside = solid.tip.contains(p);
    if (exact > 2e-3) {  // beyond the tessellation's chord tolerance the ideal solid decides the sign
      ++signs_checked;
      CHECK((sdf < 0) == inside);
    }
    const double error = std::abs(std::abs(sdf) - exact);
    worst = std::max(worst, error);
    sum += error;
    ++in_band;
    const Eigen::Vector3d g = level_set.gradient(p);
    CHECK(g.norm() < 1.2);
  }
  INFO("points " << in_band << ", worst error " << worst << " mm, mean " << sum / in_band << " mm");
  REQUIRE(in_band >= 100);
  CHECK(signs_checked > 50);
  CHECK(worst < 0.5 * options.voxel_mm);
}

TEST_CASE("level-set sign is right far from the surface, where values clamp", "[mesher][levelset][slow]") {
  const CadSolid solid = build_cad_solid(preset_recipe("SB"), false);
  const NeedleLevelSet level_set(solid.surface, LevelSetOptions{});
  std::mt19937 random(11);
  std::uniform_real_distribution<double> x(-39.5, 1.0), yz(-0.8, 0.8);
  int checked = 0;
  for (int k = 0; k < 3000; ++k) {
    const Eigen::Vector3d p(x(random), yz(random), yz(random));
    const double exact = brute_force_distance(solid.surface, p);
    if (exact < 2 * level_set.voxel_mm()) continue;
    ++checked;
    REQUIRE((level_set.signed_distance_mm(p) < 0) == solid.tip.contains(p));
    CHECK(std::abs(level_set.signed_distance_mm(p)) <= level_set.band_mm() * (1 + 1e-6));
  }
  CHECK(checked > 2000);
}

TEST_CASE("particles inside a needle pushed into the block are the ones the ideal solid contains", "[mesher][levelset][particles][slow]") {
  const CadSolid solid = build_cad_solid(preset_recipe("HMB"), false);
  const NeedleLevelSet level_set(solid.surface, LevelSetOptions{});
  LatticeOptions lattice;
  lattice.spacing_mm = 0.1;
  TissueBox box;
  box.max_mm = Eigen::Vector3d(8, 1, 1);
  box.min_mm = Eigen::Vector3d(0, -1, 0);
  const ParticleSet particles = make_particle_lattice(box, lattice);
  const Eigen::Vector3d offset(6.0, 0, 0);
  const PenetrationReport report = find_penetrations(level_set, particles.x_mm, offset);
  std::vector<bool> found(static_cast<size_t>(particles.num_particles()), false);
  for (int i : report.inside) found[static_cast<size_t>(i)] = true;
  int ideal_inside = 0, disagreements_far_from_surface = 0, near_surface = 0;
  for (int i = 0; i < particles.num_particles(); ++i) {
    const Eigen::Vector3d p = particles.x_mm.row(i).transpose() - offset;
    const bool inside = solid.tip.contains(p);
    ideal_inside += inside;
    const bool near = brute_force_distance(solid.surface, p) <= 2 * level_set.voxel_mm();
    near_surface += near;  // many lattice points lie exactly on the rod (0.3^2 + 0.4^2 = 0.5^2)
    if (inside != found[static_cast<size_t>(i)] && !near) ++disagreements_far_from_surface;
  }
  CHECK(ideal_inside > 100);
  CHECK(disagreements_far_from_surface == 0);
  CHECK(std::abs(static_cast<int>(report.inside.size()) - ideal_inside) <= near_surface);
  CHECK(report.depth_saturated);  // the needle is 1 mm thick, far deeper than the band
}

TEST_CASE("level-set input errors", "[mesher][levelset][errors]") {
  CadSolid solid = build_cad_solid(preset_recipe("SB"), true);
  LevelSetOptions bad;
  bad.voxel_mm = 0;
  CHECK_THROWS_AS(NeedleLevelSet(solid.surface, bad), InputError);
  TriSurface open = solid.surface;
  open.F.conservativeResize(open.F.rows() - 1, 3);
  open.face_tag.conservativeResize(open.face_tag.size() - 1);
  CHECK_THROWS_AS(NeedleLevelSet(open, LevelSetOptions{}), InputError);
}
