#include "apps/tip_command.h"

#include <filesystem>
#include <fmt/format.h>
#include <iostream>
#include <nlohmann/json.hpp>

#include "runs/recipe_json.h"
#include "apps/tip_source.h"
#include "geometry/cad_solid.h"
#include "core/input_error.h"
#include "geometry/mesh_io.h"
#include "geometry/render_png.h"
#include "geometry/section_properties.h"
#include "geometry/surface_measures.h"
#include "geometry/tip_report.h"

namespace needle {
namespace {

using nlohmann::json;

struct TipOptions {
  TipSource source;
  std::string analyze_file, out_file, png_file;
  bool half = false, json_output = false, ascii_stl = false;
  double section_step_mm = 0.5;
};

json vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

json sections_json(const std::vector<SectionProperties>& sections) {
  json out = json::array();
  for (const SectionProperties& s : sections)
    out.push_back({{"x_mm", s.x_mm}, {"area_mm2", s.area_mm2}, {"centroid_y_mm", s.centroid_y_mm},
                   {"centroid_z_mm", s.centroid_z_mm}, {"I_z_mm4", s.I_z_mm4}, {"I_y_mm4", s.I_y_mm4}});
  return out;
}

json report_json(const TipReport& r, const GrindingRecipe& recipe) {
  json facets = json::array();
  for (const FacetReport& f : r.facets)
    facets.push_back({{"name", f.name}, {"tilt_deg", f.tilt_deg}, {"rotation_deg", f.rotation_deg},
                      {"normal", vec(f.normal)}, {"point_mm", vec(f.point_mm)}, {"area_mm2", f.area_mm2},
                      {"area_exact_mm2", f.area_exact_mm2},
                      {"area_error_rel", f.area_exact_mm2 > 0 ? f.area_mm2 / f.area_exact_mm2 - 1 : 0.0}});
  json faces = json::object();
  for (const auto& [name, area] : r.face_areas_mm2) faces[name] = area;
  json out = {{"name", r.name},
              {"half_model", r.half_model},
              {"d_a_mm", r.d_a_mm ? json(*r.d_a_mm) : json(nullptr)},
              {"tip_point_mm", vec(r.tip_point_mm)},
              {"tip_point_exact_mm", vec(r.tip_point_exact_mm)},
              {"tip_length_mm", r.tip_length_mm},
              {"facets", facets},
              {"face_areas_mm2", faces},
              {"surface_area_mm2", r.surface_area_mm2},
              {"volume_mm3", r.volume_mm3},
              {"volume_exact_mm3", r.volume_exact_mm3},
              {"triangles", r.triangles},
              {"vertices", r.vertices},
              {"build_seconds", r.build_seconds},
              {"recipe", recipe_to_json(recipe)},
              {"sections", sections_json(r.sections)}};
  out["groove"] = r.groove ? json{{"face_y_mm", r.groove->face_y_mm},
                                  {"start_mm", r.groove->start_mm},
                                  {"length_mm", r.groove->length_mm},
                                  {"remaining_thickness_mm", r.groove->remaining_thickness_mm}}
                           : json(nullptr);
  return out;
}

void print_table(const TipReport& r) {
  fmt::print("tip '{}'{}: {} triangles, built in {:.3f} s\n", r.name, r.half_model ? " (half model)" : "",
             r.triangles, r.build_seconds);
  fmt::print("  tip point A   ({:.6f}, {:.6f}, {:.6f}) mm\n", r.tip_point_mm.x(), r.tip_point_mm.y(), r.tip_point_mm.z());
  if (r.d_a_mm) fmt::print("  d_a           {:+.4f} mm\n", *r.d_a_mm);
  if (r.groove)
    fmt::print("  groove        face y {:.4f} mm, starts {:.3f} mm behind A, {:.3f} mm long\n", r.groove->face_y_mm,
               r.groove->start_mm, r.groove->length_mm);
  fmt::print("  tip length    {:.4f} mm\n", r.tip_length_mm);
  fmt::print("  volume        {:.5f} mm3 (smooth solid {:.5f}, {:+.3f} %)\n", r.volume_mm3, r.volume_exact_mm3,
             100 * (r.volume_mm3 / r.volume_exact_mm3 - 1));
  fmt::print("  {:<12} {:>8} {:>9} {:>12} {:>12} {:>9}\n", "facet", "tilt", "rotation", "area mm2", "exact mm2", "error %");
  for (const FacetReport& f : r.facets)
    fmt::print("  {:<12} {:>8.2f} {:>9.2f} {:>12.6f} {:>12.6f} {:>9.4f}\n", f.name, f.tilt_deg, f.rotation_deg,
               f.area_mm2, f.area_exact_mm2, f.area_exact_mm2 > 0 ? 100 * (f.area_mm2 / f.area_exact_mm2 - 1) : 0.0);
  for (const auto& [name, area] : r.face_areas_mm2) {
    bool facet = false;
    for (const FacetReport& f : r.facets) facet = facet || f.name == name;
    if (!facet) fmt::print("  {:<12} {:>8} {:>9} {:>12.6f}\n", name, "", "", area);
  }
}

// The reported cross-sections over a length, refused before any work when there would be too many.
void check_section_count(double length_mm, double step_mm) {
  constexpr double kMaxSections = 1.0e4;
  const double sections = length_mm / step_mm;
  NEEDLE_REQUIRE(sections <= kMaxSections, fmt::format("--section-step-mm {} makes about {:.3g} cross-sections over {:.3g} mm (limit {:.0e}): "
                                                       "use a larger step (default 0.5)",
                                                       step_mm, sections, length_mm, kMaxSections));
}

void analyze_file(const TipOptions& o) {
  const TriSurface surface = read_surface(o.analyze_file);
  const Eigen::Vector3d tip = most_distal_point(surface);
  std::vector<double> stations;
  const double min_x = surface.V.col(0).minCoeff();
  check_section_count(tip.x() - min_x, o.section_step_mm);
  for (double x = tip.x() - 0.25 * o.section_step_mm; x > min_x; x -= o.section_step_mm) stations.push_back(x);
  std::reverse(stations.begin(), stations.end());
  json faces = json::object();
  const std::vector<double> areas = area_by_tag_mm2(surface);
  for (size_t t = 0; t < areas.size(); ++t) faces[surface.tag_names[t]] = areas[t];
  const json out = {{"file", o.analyze_file},
                    {"triangles", surface.num_faces()},
                    {"vertices", surface.num_vertices()},
                    {"closed_manifold", true},
                    {"tip_point_mm", vec(tip)},
                    {"bounding_box_mm", {vec(surface.V.colwise().minCoeff()), vec(surface.V.colwise().maxCoeff())}},
                    {"surface_area_mm2", surface_area_mm2(surface)},
                    {"face_areas_mm2", faces},
                    {"volume_mm3", enclosed_volume_mm3(surface)},
                    {"sections", sections_json(surface_sections(surface, stations))}};
  if (o.json_output) {
    std::cout << out.dump(2) << "\n";
  } else {
    fmt::print("'{}': closed manifold, {} triangles\n  tip point ({:.6f}, {:.6f}, {:.6f}) mm\n  area {:.5f} mm2, volume {:.5f} mm3\n",
               o.analyze_file, surface.num_faces(), tip.x(), tip.y(), tip.z(), surface_area_mm2(surface),
               enclosed_volume_mm3(surface));
  }
}

void run_tip(const TipOptions& o) {
  if (!o.analyze_file.empty()) {
    NEEDLE_REQUIRE(!o.source.given(),
                   "--analyze reads a tip from a file: do not combine it with --preset, --d-a or --recipe");
    NEEDLE_REQUIRE(o.out_file.empty() && o.png_file.empty(),
                   "--analyze only reads and measures a surface: --out and --png write a tip built from --preset, --d-a or --recipe");
    analyze_file(o);
    return;
  }
  const GrindingRecipe recipe = recipe_from_source(o.source);
  check_section_count(recipe.rod.length_mm, o.section_step_mm);
  // Check output paths before any work, so a bad path costs nothing and writes nothing.
  SurfaceFormat format{};
  if (!o.out_file.empty()) format = surface_format_from_path(o.out_file, o.ascii_stl);
  NEEDLE_REQUIRE(o.png_file.empty() || std::filesystem::path(o.png_file).extension() == ".png",
                 fmt::format("'{}': --png writes a PNG picture and needs a .png file", o.png_file));
  for (const std::string& path : {o.out_file, o.png_file}) {
    if (path.empty()) continue;
    const std::filesystem::path dir = std::filesystem::path(path).parent_path();
    NEEDLE_REQUIRE(dir.empty() || std::filesystem::is_directory(dir),
                   fmt::format("output folder '{}' does not exist", dir.string()));
  }
  const CadSolid solid = build_cad_solid(recipe, o.half);
  const TipReport report = make_tip_report(solid, default_section_stations(solid.tip, o.section_step_mm));
  if (!o.out_file.empty()) {
    for (const std::string& written : write_surface(solid.surface, o.out_file, format))
      if (!o.json_output) fmt::print("wrote {}\n", written);
  }
  if (!o.png_file.empty()) {
    RenderOptions render;
    render.title = fmt::format("{}{}   d_a = {}   tip length {:.2f} mm", recipe.name, o.half ? " (half model)" : "",
                               report.d_a_mm ? fmt::format("{:+.2f} mm", *report.d_a_mm) : "n/a", report.tip_length_mm);
    render.view_from_x_mm = -std::max(report.tip_length_mm + 1.0, report.groove ? report.groove->start_mm + 1.5 : 0.0);
    render_tip_png(solid.surface, o.png_file, render);
    if (!o.json_output) fmt::print("wrote {}\n", o.png_file);
  }
  if (o.json_output) std::cout << report_json(report, recipe).dump(2) << "\n";
  else print_table(report);
}

}  // namespace

void add_tip_command(CLI::App& app) {
  auto options = std::make_shared<TipOptions>();
  CLI::App* tip = app.add_subcommand("tip", "Build a needle tip from a grinding recipe; report its numbers, export it, draw it");
  add_tip_source_options(*tip, options->source);
  tip->add_flag("--half", options->half, "Half model z >= 0 with the symmetry face tagged (for the solver)");
  tip->add_option("--out", options->out_file, "Write the surface: .stl .obj .ply .glb .gltf");
  tip->add_flag("--ascii", options->ascii_stl, "Write STL as ASCII instead of binary");
  tip->add_option("--png", options->png_file, "Draw the tip, each facet in its own colour, to this PNG");
  tip->add_option("--section-step-mm", options->section_step_mm, "Spacing of the reported cross-sections")->capture_default_str();
  tip->add_flag("--json", options->json_output, "Print the report as JSON on stdout");
  tip->add_option("--analyze", options->analyze_file, "Analyse a tip surface file (STL/OBJ/PLY/glTF) instead of building one");
  tip->callback([options] {
    NEEDLE_REQUIRE(options->section_step_mm > 0, "--section-step-mm must be positive");
    run_tip(*options);
  });
}

}  // namespace needle
