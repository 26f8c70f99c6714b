#include "apps/mesh_command.h"

#include <chrono>
#include <filesystem>
#include <fmt/format.h>
#include <iostream>
#include <nlohmann/json.hpp>

#include "apps/tip_source.h"
#include "geometry/cad_solid.h"
#include "geometry/exact_measures.h"
#include "core/input_error.h"
#include "geometry/mesh_io.h"
#include "geometry/surface_measures.h"
#include "mesher/mesh_quality.h"
#include "mesher/msh_file.h"
#include "mesher/needle_mesher.h"
#include "mesher/vtk_files.h"

namespace needle {
namespace {

using nlohmann::json;

struct MeshCommandOptions {
  TipSource source;
  std::string surface_file, route = "exact";
  std::vector<std::string> out_files;
  NeedleMeshOptions mesh;
  bool half = false, json_output = false, no_optimize = false;
};

void check_output_paths(const std::vector<std::string>& paths) {
  for (const std::string& path : paths) {
    const std::filesystem::path p(path);
    NEEDLE_REQUIRE(p.extension() == ".msh" || p.extension() == ".vtu",
                   fmt::format("'{}': mesh output must be .msh (gmsh) or .vtu (ParaView)", path));
    const std::filesystem::path dir = p.parent_path();
    NEEDLE_REQUIRE(dir.empty() || std::filesystem::is_directory(dir), fmt::format("output folder '{}' does not exist", dir.string()));
  }
}

json quality_json(const MeshQuality& q) {
  return {{"min_radius_ratio", q.min_radius_ratio},     {"mean_radius_ratio", q.mean_radius_ratio},
          {"min_dihedral_deg", q.min_dihedral_deg},     {"max_dihedral_deg", q.max_dihedral_deg},
          {"min_scaled_jacobian", q.min_scaled_jacobian}, {"inverted_tets", q.inverted_tets},
          {"min_edge_mm", q.min_edge_mm},               {"mean_edge_mm", q.mean_edge_mm},
          {"max_edge_mm", q.max_edge_mm}};
}

void run_mesh(MeshCommandOptions& o) {
  NEEDLE_REQUIRE(o.source.given() != !o.surface_file.empty(), "say what to mesh: a tip (--preset, --d-a or --recipe) or --surface FILE");
  NEEDLE_REQUIRE(o.route == "exact" || o.route == "surface", "--route must be 'exact' or 'surface'");
  NEEDLE_REQUIRE(o.surface_file.empty() || !o.half, "--half applies to tips; a surface file is meshed as it is");
  o.mesh.optimize = !o.no_optimize;
  const NeedleMeshOptions resolved = o.mesh.resolved();
  check_output_paths(o.out_files);

  json report = json::object();
  TetMesh mesh;
  const auto start = std::chrono::steady_clock::now();
  double cad_volume = 0;
  json facet_exact = json::object();
  if (!o.surface_file.empty()) {
    const TriSurface surface = read_surface(o.surface_file);
    cad_volume = enclosed_volume_mm3(surface);
    mesh = mesh_surface(surface, resolved);
    report["source"] = o.surface_file;
    report["route"] = "surface";
  } else {
    const GrindingRecipe recipe = recipe_from_source(o.source);
    const TipGeometry tip = resolve_tip(recipe);
    mesh = o.route == "exact" ? mesh_needle(tip, o.half, resolved)
                              : mesh_surface(build_cad_solid(recipe, o.half).surface, resolved);
    ExactOptions exact;
    exact.half_model = o.half;
    cad_volume = exact_volume_mm3(tip, exact);
    for (size_t i = 0; i < tip.facets.size(); ++i)
      facet_exact[tip.facets[i].name] = exact_facet_area_mm2(tip, static_cast<int>(i), exact);
    report["source"] = recipe.name;
    report["route"] = o.route;
    const auto d_a = tip.d_a_mm();
    report["d_a_mm"] = d_a ? json(*d_a) : json(nullptr);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const MeshQuality q = measure_quality(mesh);

  std::vector<std::string> written;
  for (const std::string& path : o.out_files) {
    if (std::filesystem::path(path).extension() == ".msh") {
      write_msh(mesh, path);
    } else {
      // Per-tet radius ratio, so that ParaView can show where the worst tets are.
      VtkField ratio{"radius_ratio", Eigen::MatrixXd(mesh.num_tets(), 1)};
      for (int t = 0; t < mesh.num_tets(); ++t)
        ratio.values(t, 0) = tet_radius_ratio(mesh.X.row(mesh.T(t, 0)), mesh.X.row(mesh.T(t, 1)),
                                              mesh.X.row(mesh.T(t, 2)), mesh.X.row(mesh.T(t, 3)));
      write_vtu(path, mesh, {ratio});
    }
    written.push_back(path);
  }

  json areas = json::object();
  for (size_t i = 0; i < mesh.tag_names.size(); ++i) areas[mesh.tag_names[i]] = q.boundary_area_by_tag_mm2[i];
  report["half_model"] = o.half;
  report["order"] = mesh.order;
  report["element"] = mesh.order == 2 ? "T10" : "T4";
  report["options"] = {{"size_mm", resolved.size_mm}, {"tip_size_mm", resolved.tip_size_mm},
                       {"edge_size_mm", resolved.edge_size_mm}, {"shaft_size_mm", resolved.shaft_size_mm},
                       {"grading_mm", resolved.grading_mm}, {"elements_per_circle", resolved.elements_per_circle},
                       {"threads", resolved.threads}, {"optimize", resolved.optimize}};
  report["nodes"] = q.nodes;
  report["tets"] = q.tets;
  report["boundary_faces"] = q.boundary_faces;
  report["quality"] = quality_json(q);
  report["volume_mm3"] = q.volume_mm3;
  report["cad_volume_mm3"] = cad_volume;
  report["volume_error_rel"] = q.volume_mm3 / cad_volume - 1.0;
  report["boundary_tags"] = mesh.tag_names;
  report["face_areas_mm2"] = areas;
  if (!facet_exact.empty()) report["facet_areas_exact_mm2"] = facet_exact;
  report["mesh_seconds"] = seconds;
  report["files"] = written;

  if (o.json_output) {
    std::cout << report.dump(2) << "\n";
    return;
  }
  fmt::print("{} mesh of '{}'{}: {} nodes, {} tets, {} boundary faces in {:.2f} s\n", report["element"].get<std::string>(),
             report["source"].get<std::string>(), o.half ? " (half model)" : "", q.nodes, q.tets, q.boundary_faces, seconds);
  fmt::print("  volume       {:.5f} mm3 (CAD {:.5f}, {:+.4f} %)\n", q.volume_mm3, cad_volume, 100 * (q.volume_mm3 / cad_volume - 1));
  fmt::print("  quality      radius ratio min {:.3f} mean {:.3f}; dihedral {:.1f}..{:.1f} deg; scaled Jacobian min {:.3f}; {} inverted\n",
             q.min_radius_ratio, q.mean_radius_ratio, q.min_dihedral_deg, q.max_dihedral_deg, q.min_scaled_jacobian, q.inverted_tets);
  fmt::print("  edges        {:.4f} .. {:.4f} mm, mean {:.4f} mm\n", q.min_edge_mm, q.max_edge_mm, q.mean_edge_mm);
  for (size_t i = 0; i < mesh.tag_names.size(); ++i)
    fmt::print("  {:<12} {:>10.5f} mm2{}\n", mesh.tag_names[i], q.boundary_area_by_tag_mm2[i],
               facet_exact.contains(mesh.tag_names[i])
                   ? fmt::format("  (exact {:.5f})", facet_exact[mesh.tag_names[i]].get<double>()) : "");
  for (const std::string& path : written) fmt::print("wrote {}\n", path);
}

}  // namespace

void add_mesh_command(CLI::App& app) {
  auto o = std::make_shared<MeshCommandOptions>();
  CLI::App* cmd = app.add_subcommand("mesh", "Tetrahedral (T4/T10) gmsh mesh of a needle tip, refined at the tip and the groove edges");
  add_tip_source_options(*cmd, o->source);
  cmd->add_option("--surface", o->surface_file, "Mesh the solid inside a closed surface file (STL/OBJ/PLY/glTF) instead of a tip");
  cmd->add_option("--route", o->route, "exact: rebuild the ideal solid in OpenCASCADE (curved T10 shaft); surface: fill the CAD triangles")
      ->capture_default_str();
  cmd->add_option("--order", o->mesh.order, "1: 4-node tets, 2: 10-node tets")->capture_default_str();
  cmd->add_option("--size-mm,--mesh-size-mm", o->mesh.size_mm, "Target edge length over the tip and the groove (--mesh-size-mm as in run)")->capture_default_str();
  cmd->add_option("--tip-size-mm", o->mesh.tip_size_mm, "Edge length at tip point A (default size/2)");
  cmd->add_option("--edge-size-mm", o->mesh.edge_size_mm, "Edge length along sharp facet and groove edges (default size/2)");
  cmd->add_option("--shaft-size-mm", o->mesh.shaft_size_mm, "Edge length along the shaft behind the groove (default 2 x size)");
  cmd->add_option("--grading-mm", o->mesh.grading_mm, "Distance over which sizes blend from fine to coarse")->capture_default_str();
  cmd->add_option("--elements-per-circle", o->mesh.elements_per_circle, "gmsh curvature sizing on the shaft (0: off)")->capture_default_str();
  cmd->add_option("--threads", o->mesh.threads, "1: reproducible Delaunay; other: parallel HXT on that many threads (0: all)")->capture_default_str();
  cmd->add_flag("--no-optimize", o->no_optimize, "Skip gmsh's tet and high-order optimisation");
  cmd->add_flag("--half", o->half, "Half model z >= 0 with the symmetry face tagged");
  cmd->add_option("--out", o->out_files, "Write the mesh: .msh (gmsh 4.1 ASCII) and/or .vtu (ParaView); repeatable");
  cmd->add_flag("--json", o->json_output, "Print the report (counts, quality, volume) as JSON");
  cmd->callback([o] { run_mesh(*o); });
}

}  // namespace needle
