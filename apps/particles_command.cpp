// `needle particles`: the tissue particle lattice, written for ParaView, optionally classified
// against a needle pushed into the block (OpenVDB level set of the CAD surface).
#include <filesystem>
#include <fmt/format.h>
#include <iostream>
#include <nlohmann/json.hpp>

#include "apps/mesh_command.h"
#include "apps/tip_source.h"
#include "geometry/cad_solid.h"
#include "core/input_error.h"
#include "mesher/needle_level_set.h"
#include "mesher/particle_lattice.h"
#include "mesher/vtk_files.h"

namespace needle {
namespace {

using nlohmann::json;

struct ParticlesOptions {
  TipSource source;
  std::vector<double> box_min{0, -4, 0}, box_max{40, 4, 2}, roi_min, roi_max;
  std::vector<std::string> faces{"free", "free", "fixed", "fixed", "symmetry", "fixed"};
  double spacing_mm = 0.4, insert_mm = 0.0;
  int roi_refinement = 2;
  LevelSetOptions level_set;
  std::string out_file;
  bool json_output = false;
};

Eigen::Vector3d vec3(const std::vector<double>& v) { return {v[0], v[1], v[2]}; }

void run_particles(const ParticlesOptions& o) {
  TissueBox box;
  box.min_mm = vec3(o.box_min);
  box.max_mm = vec3(o.box_max);
  for (int k = 0; k < 6; ++k) box.faces[static_cast<size_t>(k)] = face_condition_from_name(o.faces[static_cast<size_t>(k)]);
  LatticeOptions lattice;
  lattice.spacing_mm = o.spacing_mm;
  NEEDLE_REQUIRE(o.roi_min.empty() == o.roi_max.empty(), "give both --roi-min-mm and --roi-max-mm, or neither");
  if (!o.roi_min.empty()) lattice.region_of_interest = RegionOfInterest{vec3(o.roi_min), vec3(o.roi_max), o.roi_refinement};
  NEEDLE_REQUIRE(o.source.given() || o.insert_mm == 0.0, "--insert-mm needs a needle: --preset, --d-a or --recipe");
  NEEDLE_REQUIRE(std::isfinite(o.insert_mm) && o.insert_mm >= 0, "--insert-mm must be a length >= 0");
  if (!o.out_file.empty()) {
    NEEDLE_REQUIRE(std::filesystem::path(o.out_file).extension() == ".vtp", fmt::format("'{}': particles are written as .vtp", o.out_file));
    const auto dir = std::filesystem::path(o.out_file).parent_path();
    NEEDLE_REQUIRE(dir.empty() || std::filesystem::is_directory(dir), fmt::format("output folder '{}' does not exist", dir.string()));
  }
  const ParticleSet particles = make_particle_lattice(box, lattice);
  const Eigen::Index n = particles.num_particles();

  json report = {{"particles", n},
                 {"nodes_per_axis", {particles.nodes_per_axis.x(), particles.nodes_per_axis.y(), particles.nodes_per_axis.z()}},
                 {"spacing_mm", o.spacing_mm},
                 {"min_spacing_mm", particles.spacing_mm.minCoeff()},
                 {"total_volume_mm3", particles.volume_mm3.sum()},
                 {"box_volume_mm3", (box.max_mm - box.min_mm).prod()},
                 {"box_min_mm", o.box_min},
                 {"box_max_mm", o.box_max},
                 {"faces", o.faces}};
  for (auto [name, bit] : {std::pair{"fixed", kParticleFixed}, {"symmetry", kParticleSymmetry}, {"free_surface", kParticleFreeSurface}}) {
    int count = 0;
    for (Eigen::Index i = 0; i < n; ++i) count += (particles.flags[i] & bit) ? 1 : 0;
    report[std::string(name) + "_particles"] = count;
  }

  std::vector<VtkField> fields{{"volume_mm3", particles.volume_mm3}, {"spacing_mm", particles.spacing_mm}};
  for (auto [name, bit] : {std::pair{"fixed", kParticleFixed}, {"symmetry", kParticleSymmetry}, {"free_surface", kParticleFreeSurface}}) {
    Eigen::VectorXd flag(n);
    for (Eigen::Index i = 0; i < n; ++i) flag[i] = (particles.flags[i] & bit) ? 1.0 : 0.0;
    fields.push_back({name, flag});
  }
  if (o.source.given()) {
    const CadSolid solid = build_cad_solid(recipe_from_source(o.source), false);
    const NeedleLevelSet level_set(solid.surface, o.level_set);
    const Eigen::Vector3d offset(box.min_mm.x() + o.insert_mm, 0, 0);  // tip point A this far into the block
    const PenetrationReport inside = find_penetrations(level_set, particles.x_mm, offset);
    Eigen::VectorXd in = Eigen::VectorXd::Zero(n);
    for (int i : inside.inside) in[i] = 1.0;
    fields.push_back({"needle_distance_mm", inside.signed_distance_mm});
    fields.push_back({"inside_needle", in});
    report["needle"] = {{"source", solid.tip.name},
                        {"tip_point_x_mm", offset.x()},
                        {"inside_particles", inside.inside.size()},
                        {"max_depth_mm", inside.max_depth_mm},
                        {"depth_saturated", inside.depth_saturated},
                        {"level_set", {{"voxel_mm", level_set.voxel_mm()}, {"band_mm", level_set.band_mm()},
                                       {"active_voxels", level_set.active_voxels()}, {"memory_bytes", level_set.memory_bytes()},
                                       {"build_seconds", level_set.build_seconds()}}}};
  }
  if (!o.out_file.empty()) write_vtp(o.out_file, particles.x_mm, fields);
  if (o.json_output) {
    std::cout << report.dump(2) << "\n";
    return;
  }
  fmt::print("{} particles ({} x {} x {}), volume {:.6f} of {:.6f} mm3; {} fixed, {} on the symmetry plane, {} on free faces\n", n,
             particles.nodes_per_axis.x(), particles.nodes_per_axis.y(), particles.nodes_per_axis.z(),
             particles.volume_mm3.sum(), (box.max_mm - box.min_mm).prod(), report["fixed_particles"].get<int>(),
             report["symmetry_particles"].get<int>(), report["free_surface_particles"].get<int>());
  if (report.contains("needle"))
    fmt::print("needle '{}' with A at x = {} mm: {} particles inside, deepest {:.4f} mm (level set {} voxels of {} mm, {:.2f} s)\n",
               report["needle"]["source"].get<std::string>(), report["needle"]["tip_point_x_mm"].get<double>(),
               report["needle"]["inside_particles"].get<size_t>(), report["needle"]["max_depth_mm"].get<double>(),
               report["needle"]["level_set"]["active_voxels"].get<long>(), o.level_set.voxel_mm,
               report["needle"]["level_set"]["build_seconds"].get<double>());
  if (!o.out_file.empty()) fmt::print("wrote {}\n", o.out_file);
}

}  // namespace

void add_particles_command(CLI::App& app) {
  auto o = std::make_shared<ParticlesOptions>();
  CLI::App* cmd = app.add_subcommand("particles", "Tissue particle lattice (SPG) of a box, optionally classified against a needle");
  cmd->add_option("--box-min-mm", o->box_min, "Box corner (x y z); default the paper's half block 0 -4 0")->expected(3);
  cmd->add_option("--box-max-mm", o->box_max, "Box corner (x y z); default 40 4 2")->expected(3);
  cmd->add_option("--spacing-mm", o->spacing_mm, "Particle spacing (rounded to fit the box)")->capture_default_str();
  cmd->add_option("--faces", o->faces, "Conditions of faces x-, x+, y-, y+, z-, z+: free, fixed or symmetry")->expected(6);
  cmd->add_option("--roi-min-mm", o->roi_min, "Region of interest corner (x y z), refined along each axis it spans")->expected(3);
  cmd->add_option("--roi-max-mm", o->roi_max, "Region of interest corner (x y z)")->expected(3);
  cmd->add_option("--roi-refinement", o->roi_refinement, "Spacing divisor inside the region of interest")->capture_default_str();
  add_tip_source_options(*cmd, o->source);
  cmd->add_option("--insert-mm", o->insert_mm, "Put tip point A this far into the block (x) and report particles inside the needle")
      ->capture_default_str();
  cmd->add_option("--voxel-mm", o->level_set.voxel_mm, "Level-set voxel size")->capture_default_str();
  cmd->add_option("--band-voxels", o->level_set.half_width_voxels, "Level-set narrow-band half width")->capture_default_str();
  cmd->add_option("--out", o->out_file, "Write the particles as .vtp (ParaView)");
  cmd->add_flag("--json", o->json_output, "Print the report as JSON");
  cmd->callback([o] { run_particles(*o); });
}

}  // namespace needle
