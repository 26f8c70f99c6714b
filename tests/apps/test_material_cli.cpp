// `needle material-test` as a user runs it: JSON curve against the closed form, CSV + PNG files, and
// one clear error (exit 2, no files) for a bad card.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "solver/tissue/tissue_material.h"
#include "tests/apps/cli_run.h"

namespace fs = std::filesystem;

TEST_CASE("needle material-test --json prints the curve and its error", "[cli][material][slow]") {
  const auto r = needle_test::run("material-test --json --max-strain 0.6 --samples 7 --E-MPa 0.1 --rate-law off");
  REQUIRE(r.exit_code == 0);
  const auto report = nlohmann::json::parse(r.out);
  const auto strain = report.at("true_strain").get<std::vector<double>>();
  const auto stress = report.at("true_stress_MPa").get<std::vector<double>>();
  REQUIRE(strain.size() == 7);
  REQUIRE(stress.size() == 7);
  needle::TissueMaterial card;
  card.E_MPa = 0.1;
  card.rate_law = needle::RateLaw::off;
  // Compare with the card's curve computed here, not with the command's own column.
  const double peak = needle::uniaxial_true_stress_MPa(card, strain.back(), 0.05);
  for (size_t k = 0; k < strain.size(); ++k)
    CHECK(std::abs(stress[k] - needle::uniaxial_true_stress_MPa(card, strain[k], 0.05)) < 0.03 * peak);
  CHECK(strain.back() == Approx(0.6).epsilon(1e-3));
  CHECK(report.at("material").at("rate_law") == "off");
}

TEST_CASE("needle material-test writes a CSV and a PNG, bad cards fail cleanly", "[cli][material][slow]") {
  const fs::path dir = fs::temp_directory_path() / "needle_material_cli";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string csv = (dir / "curve.csv").string(), png = (dir / "curve.png").string();
  auto r = needle_test::run("material-test --max-strain 0.3 --samples 4 --csv " + csv + " --png " + png);
  REQUIRE(r.exit_code == 0);
  std::ifstream in(csv);
  std::string header, line;
  std::getline(in, header);
  CHECK(header.rfind("true_strain,true_stress_MPa", 0) == 0);
  int rows = 0;
  while (std::getline(in, line)) ++rows;
  CHECK(rows == 4);
  CHECK(fs::file_size(png) > 1000);
  for (const std::string bad : {"--E-MPa -1", "--nu 0.5", "--n 0.9", "--dilation 0.5", "--rate-law maybe", "--spacing-mm 0"}) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    r = needle_test::run("material-test " + bad + " --csv " + csv + " --png " + png);
    INFO(bad);
    CHECK(r.exit_code == 2);
    CHECK(fs::is_empty(dir));
  }
  fs::remove_all(dir);
}
