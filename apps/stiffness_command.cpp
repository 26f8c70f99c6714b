// `needle stiffness`: the needle clamped at --free-length-mm behind tip point A, loaded at the tip in
// y and in z (spread over the tip's facets), solved by the FE model; prints the tip compliance and
// the first bending frequencies, next to Euler-Bernoulli beam theory with the real sections.
#include "apps/stiffness_command.h"

#include <chrono>
#include <fmt/format.h>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include "apps/cli_checks.h"
#include "runs/needle_build.h"
#include "apps/tip_source.h"
#include "geometry/exact_measures.h"
#include "core/input_error.h"
#include "solver/needle/beam_reference.h"
#include "solver/needle/fe_needle.h"
#include "solver/needle/needle_stiffness.h"
#include "core/parallel.h"

namespace needle {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

struct StiffnessOptions {
  TipSource source;
  bool plain_rod = false;
  double rod_diameter_mm = 1.0;
  double free_length_mm = 30.0;
  NeedleMeshOptions mesh;
  NeedleMaterial material;
  double density_g_per_cm3 = 8.0;
  int modes = 6, threads = 0;
  bool json_output = false;
};

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Beam theory with the ideal solid's own sections (independent of the mesh).
json beam_reference(const TipGeometry& tip, const StiffnessResult& fe, const NeedleMaterial& m, bool plain_rod) {
  ExactOptions exact;
  exact.circle_vertices = 4096;
  std::vector<double> breaks;
  if (tip.groove) breaks = {tip.groove->back_x_mm, tip.groove->front_x_mm};
  std::map<double, SectionProperties> sections;  // both integrals sample the same x
  auto section = [&](double x) -> const SectionProperties& {
    auto it = sections.find(x);
    return it != sections.end() ? it->second : sections.emplace(x, exact_section(tip, x, exact)).first->second;
  };
  auto I_z = [&](double x) { return section(x).I_z_mm4; };
  auto I_y = [&](double x) { return section(x).I_y_mm4; };
  const double clamp = tip.base_x_mm, load = fe.load_centroid_x_mm, point = tip.tip_point.x();
  json beam = {{"compliance_y_mm_per_N", cantilever_compliance_mm_per_N(I_z, m.youngs_modulus_MPa, clamp, load, point, breaks)},
               {"compliance_z_mm_per_N", cantilever_compliance_mm_per_N(I_y, m.youngs_modulus_MPa, clamp, load, point, breaks)}};
  if (plain_rod) {
    const double r = tip.radius_mm, L = -tip.base_x_mm, area = M_PI * r * r, I = M_PI * std::pow(r, 4) / 4;
    const double beta = 1.8751040687119611;  // first root of 1 + cos b cosh b = 0
    beam["frequency_hz"] = beta * beta / (2 * M_PI * L * L) * std::sqrt(m.youngs_modulus_MPa * I / (m.density_g_per_mm3 * area)) * 1000.0;
  }
  beam["note"] = "Euler-Bernoulli, clamped at the base, load at the FE load's resultant x, sections of the ideal solid";
  return beam;
}

void run_stiffness(StiffnessOptions& o) {
  NEEDLE_REQUIRE(o.plain_rod != o.source.given(), "say which needle: --preset, --d-a, --recipe, or --plain-rod");
  NEEDLE_REQUIRE(std::isfinite(o.free_length_mm) && o.free_length_mm > 0, "--free-length-mm must be positive");
  NEEDLE_REQUIRE(std::isnan(o.source.rod_length_mm), "use --free-length-mm, not --rod-length-mm: the needle is clamped at its base");
  NEEDLE_REQUIRE(o.modes >= 2 && o.modes <= 50, "--modes must be between 2 and 50");
  o.material.density_g_per_mm3 = o.density_g_per_cm3 * 1e-3;
  o.material.validate();
  const ThreadLimit threads(o.threads);
  TipGeometry tip;
  if (o.plain_rod) {
    tip = plain_rod_tip(o.rod_diameter_mm, o.free_length_mm);
  } else {
    GrindingRecipe recipe = recipe_from_source(o.source);
    recipe.rod.length_mm = o.free_length_mm;
    tip = resolve_tip(recipe);
  }
  const NeedleBuild build = build_needle(tip, false, o.mesh);
  auto t = Clock::now();
  const FeNeedle needle(build.mesh, o.material);
  const double setup_s = seconds_since(t);
  t = Clock::now();
  const StiffnessResult r = analyse_stiffness(needle, tip.tip_point, build.tip_facets, "base", o.modes);
  const double solve_s = seconds_since(t);
  const json beam = beam_reference(tip, r, o.material, o.plain_rod);

  json modes = json::array();
  for (size_t i = 0; i < r.mode_frequencies_hz.size(); ++i)
    modes.push_back({{"frequency_hz", r.mode_frequencies_hz[i]}, {"direction", r.mode_directions[i]}});
  json out = {
      {"needle", tip.name},
      {"free_length_mm", o.free_length_mm},
      {"compliance_y_mm_per_N", r.compliance_y_mm_per_N},
      {"compliance_z_mm_per_N", r.compliance_z_mm_per_N},
      {"frequency_y_hz", r.frequency_y_hz},
      {"frequency_z_hz", r.frequency_z_hz},
      {"beam_theory", beam},
      {"modes", modes},
      {"load", {{"faces", build.tip_facets}, {"resultant_x_mm", r.load_centroid_x_mm}}},
      {"tip_node_offset_mm", r.tip_node_offset_mm},
      {"mesh", {{"order", build.mesh.order}, {"size_mm", o.mesh.resolved().size_mm}, {"nodes", build.mesh.num_nodes()},
                {"elements", build.mesh.num_tets()}, {"free_dofs", r.free_dofs},
                {"straightened_tets", build.mesh.straightened_tets}}},
      {"material", {{"youngs_modulus_MPa", o.material.youngs_modulus_MPa}, {"poisson_ratio", o.material.poisson_ratio},
                    {"density_g_per_cm3", o.density_g_per_cm3}}},
      {"seconds", {{"mesh", build.mesh_seconds}, {"setup", setup_s}, {"solve_and_modes", solve_s}}},
  };
  if (o.json_output) {
    std::cout << out.dump(2) << "\n";
    return;
  }
  auto pct = [](double fe, double ref) { return 100.0 * (fe / ref - 1.0); };
  fmt::print("{} clamped {} mm behind A ({} T{} elements, {} nodes)\n", tip.name, o.free_length_mm, build.mesh.num_tets(),
             build.mesh.order == 2 ? 10 : 4, build.mesh.num_nodes());
  fmt::print("  tip compliance y  {:.5g} mm/N   (beam theory {:.5g}, {:+.2f} %)\n", r.compliance_y_mm_per_N,
             beam["compliance_y_mm_per_N"].get<double>(), pct(r.compliance_y_mm_per_N, beam["compliance_y_mm_per_N"]));
  fmt::print("  tip compliance z  {:.5g} mm/N   (beam theory {:.5g}, {:+.2f} %)\n", r.compliance_z_mm_per_N,
             beam["compliance_z_mm_per_N"].get<double>(), pct(r.compliance_z_mm_per_N, beam["compliance_z_mm_per_N"]));
  fmt::print("  first bending     {:.5g} Hz in y, {:.5g} Hz in z", r.frequency_y_hz, r.frequency_z_hz);
  if (beam.contains("frequency_hz")) fmt::print("   (beam theory {:.5g} Hz)", beam["frequency_hz"].get<double>());
  fmt::print("\n");
}

}  // namespace

void add_stiffness_command(CLI::App& app) {
  auto o = std::make_shared<StiffnessOptions>();
  CLI::App* c = app.add_subcommand("stiffness", "Tip compliance and first bending frequencies of a needle clamped behind its tip (FE)");
  add_tip_source_options(*c, o->source);
  c->add_flag("--plain-rod", o->plain_rod, "A flat-ended rod instead of a tip (the beam-theory check case)");
  c->add_option("--rod-diameter-mm", o->rod_diameter_mm, "Diameter of the plain rod")->capture_default_str();
  c->add_option("--free-length-mm", o->free_length_mm, "Distance from tip point A back to the clamp")->capture_default_str();
  c->add_option("--order", o->mesh.order, "Element order: 1 (T4) or 2 (T10)")->capture_default_str();
  c->add_option("--size-mm,--mesh-size-mm", o->mesh.size_mm, "Element size over the tip and groove (--mesh-size-mm as in run)")->capture_default_str();
  c->add_option("--shaft-size-mm", o->mesh.shaft_size_mm, "Element size along the plain shaft (default 2 x size)");
  c->add_option("--E-MPa,--needle-E-MPa", o->material.youngs_modulus_MPa, "Young's modulus of the needle")->capture_default_str();
  c->add_option("--nu", o->material.poisson_ratio, "Poisson's ratio of the needle")->capture_default_str();
  c->add_option("--density-g-per-cm3", o->density_g_per_cm3, "Density of the needle")->capture_default_str();
  c->add_option("--modes", o->modes, "Number of vibration modes to compute")->capture_default_str();
  c->add_option("--threads", o->threads, "Worker threads (0: all cores)")->capture_default_str()->check(count_check());
  c->add_flag("--json", o->json_output, "Print the results as JSON");
  c->callback([o] { run_stiffness(*o); });
}

}  // namespace needle
