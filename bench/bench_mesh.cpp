// Mesher benchmark: gmsh T10/T4 time, counts, quality and volume error for each paper preset at
// three sizes; particle lattice time; level-set build time and distance error against brute force.
// Usage: bench_mesh [sizes...]   (default 0.3 0.2 0.1 mm)
#include <chrono>
#include <cstdlib>
#include <fmt/format.h>
#include <random>
#include <vector>

#include "geometry/cad_solid.h"
#include "geometry/exact_measures.h"
#include "mesher/mesh_quality.h"
#include "mesher/needle_level_set.h"
#include "mesher/needle_mesher.h"
#include "mesher/particle_lattice.h"
#include "mesher/triangle_distance.h"

using namespace needle;
using Clock = std::chrono::steady_clock;

namespace {

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

}  // namespace

int main(int argc, char** argv) {
  std::vector<double> sizes;
  for (int i = 1; i < argc; ++i) sizes.push_back(std::atof(argv[i]));
  if (sizes.empty()) sizes = {0.3, 0.2, 0.1};

  fmt::print("gmsh needle meshes (exact OCC route, 1 thread, half model; volume error vs the smooth solid)\n");
  fmt::print("{:<5} {:>4} {:>6} {:>8} {:>8} {:>8} {:>8} {:>9} {:>9} {:>8} {:>10}\n", "tip", "elem", "size", "seconds",
             "nodes", "tets", "rr_min", "dih_min", "sJ_min", "inverted", "vol_err_%");
  for (const std::string preset : {"SB", "LMB", "AMB", "HMB"}) {
    const TipGeometry tip = resolve_tip(preset_recipe(preset));
    ExactOptions exact;
    exact.half_model = true;
    const double reference = exact_volume_mm3(tip, exact);
    for (const int order : {2, 1})
      for (const double size : sizes) {
        if (order == 1 && size != 0.2) continue;
        NeedleMeshOptions o;
        o.order = order;
        o.size_mm = size;
        const auto start = Clock::now();
        const TetMesh mesh = mesh_needle(tip, true, o);
        const double seconds = seconds_since(start);
        const MeshQuality q = measure_quality(mesh);
        fmt::print("{:<5} {:>4} {:>6.2f} {:>8.2f} {:>8} {:>8} {:>8.3f} {:>9.2f} {:>9.3f} {:>8} {:>10.4f}\n", preset,
                   order == 2 ? "T10" : "T4", size, seconds, q.nodes, q.tets, q.min_radius_ratio, q.min_dihedral_deg,
                   q.min_scaled_jacobian, q.inverted_tets, 100 * (q.volume_mm3 / reference - 1));
      }
  }

  fmt::print("\ntissue particle lattices (paper half block 40 x 8 x 2 mm)\n");
  for (const double h : {0.4, 0.2, 0.1}) {
    LatticeOptions o;
    o.spacing_mm = h;
    const auto start = Clock::now();
    const ParticleSet p = make_particle_lattice(TissueBox{}, o);
    fmt::print("  spacing {:.2f} mm: {:>9} particles in {:.4f} s, volume error {:.2e}\n", h, p.num_particles(),
               seconds_since(start), p.volume_mm3.sum() / 640.0 - 1);
  }

  fmt::print("\nOpenVDB level set of the full LMB surface: build time, memory, error vs exact distance (points in half the band)\n");
  const CadSolid solid = build_cad_solid(preset_recipe("LMB"), false);
  for (const double voxel : {0.04, 0.02, 0.01}) {
    LevelSetOptions o;
    o.voxel_mm = voxel;
    const NeedleLevelSet level_set(solid.surface, o);
    std::mt19937 random(3);
    std::uniform_real_distribution<double> x(-3.5, 0.3), yz(-0.6, 0.6);
    int n = 0;
    double worst = 0, sum = 0;
    for (int k = 0; k < 20000 && n < 300; ++k) {
      const Eigen::Vector3d p(x(random), yz(random), yz(random));
      const double d = distance_to_surface_mm(solid.surface, p);
      if (d > 0.5 * level_set.band_mm()) continue;
      const double e = std::abs(std::abs(level_set.signed_distance_mm(p)) - d);
      worst = std::max(worst, e);
      sum += e;
      ++n;
    }
    const auto query_start = Clock::now();
    double sink = 0;
    for (int k = 0; k < 1000000; ++k) sink += level_set.signed_distance_mm(Eigen::Vector3d(x(random), yz(random), yz(random)));
    const double query_seconds = seconds_since(query_start);
    fmt::print("  voxel {:.3f} mm: build {:.2f} s, {:>9} active voxels, {:>6.1f} MiB; error max {:.5f} mm ({:.2f} voxel), "
               "mean {:.5f} mm over {} points; 1e6 queries {:.2f} s{}\n",
               voxel, level_set.build_seconds(), level_set.active_voxels(), level_set.memory_bytes() / 1048576.0, worst,
               worst / voxel, sum / n, n, query_seconds, sink == 12345.678 ? " " : "");
  }
  return 0;
}
