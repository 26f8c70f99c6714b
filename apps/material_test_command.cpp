// `needle material-test`: pulls a particle specimen of the tissue card in uniaxial tension and compares
// its true stress - true strain curve with the card's closed-form MAT_018 curve. --json prints the
// curve; otherwise a CSV and a PNG plot are written.
#include "apps/material_test_command.h"

#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "apps/cli_checks.h"
#include "runs/material_json.h"
#include "core/input_error.h"
#include "geometry/mesh_io.h"
#include "plot/line_plot.h"
#include "core/parallel.h"
#include "solver/tissue/uniaxial_test.h"

namespace needle {
namespace {

struct MaterialTestOptions {
  std::string material_file;
  std::optional<double> E_MPa, k_MPa, n, nu, density_g_per_cm3, rate_C_per_ms, rate_p;
  std::string rate_law;  // empty: from the card
  std::string law;       // empty: from the card
  std::string lateral = "guided", stabilization = "penalty";
  UniaxialTestOptions test;
  int threads = 0;
  bool json_output = false;
  std::string csv_path = "material_test.csv", png_path = "material_test.png";
};

void require_folder_of(const std::string& path) {
  const auto dir = std::filesystem::path(path).parent_path();
  NEEDLE_REQUIRE(dir.empty() || std::filesystem::is_directory(dir), fmt::format("output folder '{}' does not exist", dir.string()));
}

void run_material_test(MaterialTestOptions& o) {
  TissueMaterial material = o.material_file.empty() ? TissueMaterial{} : read_material_file(o.material_file);
  if (o.E_MPa) material.E_MPa = *o.E_MPa;
  if (o.k_MPa) material.k_MPa = *o.k_MPa;
  if (o.n) material.n = *o.n;
  if (o.nu) material.nu = *o.nu;
  if (o.density_g_per_cm3) material.density_g_per_cm3 = *o.density_g_per_cm3;
  if (o.rate_C_per_ms) material.rate_C_per_ms = *o.rate_C_per_ms;
  if (o.rate_p) material.rate_p = *o.rate_p;
  if (!o.rate_law.empty()) material.rate_law = rate_law_from_name(o.rate_law);
  if (!o.law.empty()) material.law = tissue_law_from_name(o.law);
  material.validate();
  NEEDLE_REQUIRE(o.lateral == "guided" || o.lateral == "free", fmt::format("--lateral must be guided or free (got '{}')", o.lateral));
  o.test.guided_lateral = o.lateral == "guided";
  o.test.spg.stabilization = stabilization_from_name(o.stabilization);
  o.test.validate();
  NEEDLE_REQUIRE(o.threads >= 0, "--threads must be >= 0");
  if (!o.json_output) {
    NEEDLE_REQUIRE(std::filesystem::path(o.csv_path).extension() == ".csv", fmt::format("'{}': --csv needs a .csv file", o.csv_path));
    NEEDLE_REQUIRE(std::filesystem::path(o.png_path).extension() == ".png", fmt::format("'{}': --png needs a .png file", o.png_path));
    require_folder_of(o.csv_path);
    require_folder_of(o.png_path);
  }

  const ThreadLimit limit(o.threads);
  const UniaxialCurve curve = run_uniaxial_test(material, o.test);

  if (o.json_output) {
    const nlohmann::json report = {
        {"material", material_to_json(material)},
        {"yield_strain", material.law == TissueLaw::mat018 ? nlohmann::json(material.yield_strain()) : nlohmann::json(nullptr)},
        {"strain_rate_per_ms", o.test.strain_rate_per_ms},
        {"rate_factor", material.rate_factor(o.test.strain_rate_per_ms)},
        {"lateral", o.lateral},
        {"specimen_mm", {o.test.length_mm, o.test.width_mm, o.test.thickness_mm}},
        {"spacing_mm", o.test.spacing_mm},
        {"particles", curve.particles},
        {"neighbours", curve.neighbours},
        {"steps", curve.steps},
        {"runtime_s", curve.runtime_s},
        {"true_strain", curve.true_strain},
        {"true_stress_MPa", curve.true_stress_MPa},
        {"closed_form_stress_MPa", curve.closed_form_stress_MPa},
        {"particle_stress_MPa", curve.particle_stress_MPa},
        {"lateral_stress_MPa", curve.lateral_stress_MPa},
        {"plastic_strain", curve.plastic_strain},
        {"max_relative_error", curve.max_relative_error()},
        {"max_energy_balance_error", curve.max_energy_error},
        {"bonds_broken", curve.bonds_broken},
        {"rate_factor_capped", curve.rate_factor_capped}};
    std::cout << report.dump(2) << "\n";
    return;
  }
  write_file_atomically(o.csv_path, [&](const std::string& scratch) {
    std::ofstream out(scratch);
    out << "true_strain,true_stress_MPa,closed_form_stress_MPa,particle_stress_MPa,lateral_stress_MPa,plastic_strain\n";
    for (size_t k = 0; k < curve.true_strain.size(); ++k)
      out << fmt::format("{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g}\n", curve.true_strain[k], curve.true_stress_MPa[k],
                         curve.closed_form_stress_MPa[k], curve.particle_stress_MPa[k], curve.lateral_stress_MPa[k],
                         curve.plastic_strain[k]);
    if (!out) throw std::runtime_error("cannot write " + scratch);
  });
  LinePlot plot;
  plot.title = fmt::format("Uniaxial tension: E {} MPa, k {} MPa, n {}, nu {}", material.E_MPa, material.k_MPa, material.n, material.nu);
  plot.x_label = "true strain";
  plot.y_label = "true stress (MPa)";
  // The input law on a fine grid, the specimen's curve as points.
  PlotSeries law{material.law == TissueLaw::mat018
                     ? fmt::format("input law (closed-form MAT_018), rate law {} at {} /ms", rate_law_name(material.rate_law),
                                   o.test.strain_rate_per_ms)
                     : std::string("input law (closed-form stiffening elastic: 3 G eps + k eps^n)"),
                 {}, {}, plot_color(1), true, false};
  for (int k = 0; k <= 200; ++k) {
    const double e = o.test.max_strain * k / 200.0;
    law.x.push_back(e);
    law.y.push_back(uniaxial_true_stress_MPa(material, e, o.test.strain_rate_per_ms));
  }
  plot.series.push_back({fmt::format("particle specimen, {} lateral faces ({} particles)", o.lateral, curve.particles),
                         curve.true_strain, curve.true_stress_MPa, plot_color(0), false, true});
  plot.series.push_back(law);
  const RgbImage image = draw_line_plot(plot);
  write_file_atomically(o.png_path, [&](const std::string& scratch) { write_png(image, scratch); });
  fmt::print("material test: {} particles, {} steps, {:.2f} s; max deviation from the closed form {:.2f} % of peak stress\n",
             curve.particles, curve.steps, curve.runtime_s, 100 * curve.max_relative_error());
  fmt::print("wrote {} and {}\n", o.csv_path, o.png_path);
}

}  // namespace

void add_material_test_command(CLI::App& app) {
  auto o = std::make_shared<MaterialTestOptions>();
  CLI::App* cmd = app.add_subcommand("material-test",
                                     "Pull a particle specimen of the tissue card in uniaxial tension; compare with the closed-form curve");
  cmd->add_option("--material", o->material_file, "Tissue card as JSON (see data/materials/); flags below override it")->check(CLI::ExistingFile);
  cmd->add_option("--E-MPa,--tissue-E-MPa", o->E_MPa, "The tissue's Young's modulus (default 0.665, see docs/solver.md; --tissue-E-MPa as in run)");
  cmd->add_option("--k-MPa", o->k_MPa, "Power-law strength coefficient k (default 0.35)");
  cmd->add_option("--n", o->n, "Power-law hardening exponent n > 1 (default 2.75)");
  cmd->add_option("--nu", o->nu, "Poisson's ratio (default 0.45)");
  cmd->add_option("--density-g-per-cm3", o->density_g_per_cm3, "Density (default 0.98)");
  cmd->add_option("--rate-law", o->rate_law, "Cowper-Symonds factor: on (= plausible, exponent p), printed (exponent 1/p), off");
  cmd->add_option("--law", o->law, "Constitutive law: mat018 (the paper's card) or stiffening_elastic (E at small strain plus k eps^n)");
  cmd->add_option("--rate-C-per-ms", o->rate_C_per_ms, "Cowper-Symonds C (default 0.1 /ms)");
  cmd->add_option("--rate-p", o->rate_p, "Cowper-Symonds p (default 0.1)");
  cmd->add_option("--max-strain", o->test.max_strain, "Largest true strain of the test")->capture_default_str();
  cmd->add_option("--strain-rate-per-ms", o->test.strain_rate_per_ms, "Imposed true strain rate (1/ms)")->capture_default_str();
  cmd->add_option("--spacing-mm", o->test.spacing_mm, "Particle spacing of the specimen")->capture_default_str();
  cmd->add_option("--length-mm", o->test.length_mm, "Gauge length")->capture_default_str();
  cmd->add_option("--width-mm", o->test.width_mm, "Specimen width (y)")->capture_default_str();
  cmd->add_option("--thickness-mm", o->test.thickness_mm, "Specimen thickness (z)")->capture_default_str();
  cmd->add_option("--samples", o->test.samples, "Points on the curve")->capture_default_str();
  cmd->add_option("--lateral", o->lateral, "Lateral faces: guided (servo to zero lateral stress; no necking) or free")->capture_default_str();
  cmd->add_option("--stabilization", o->stabilization, "SPG stabilization: penalty, filter or none")->capture_default_str();
  cmd->add_option("--dilation", o->test.spg.dilation, "SPG support radius / spacing")->capture_default_str();
  cmd->add_option("--threads", o->threads, "Worker threads (0: all cores)")->capture_default_str()->check(count_check());
  cmd->add_flag("--json", o->json_output, "Print the curve and its error as JSON on stdout (no files)");
  cmd->add_option("--csv", o->csv_path, "Curve as CSV (without --json)")->capture_default_str();
  cmd->add_option("--png", o->png_path, "Plot of the curve against the input law (without --json)")->capture_default_str();
  cmd->callback([o] { run_material_test(*o); });
}

}  // namespace needle
