// Regression scenes: four small coupled insertions of seconds each, run by `needle simulate` as a user would,
// whose history.csv and facet_forces.csv must repeat byte for byte the ones stored in tests/data/regression/
// (regenerated only when a change of results is intended and explained in the commit). The first three were made
// by the solver before the coupled step was restructured: the FE needle subcycled in the tissue's step with the
// cannula, the penalty contact with friction, the needle's cut, the symmetry slit, the tip crack, the cutting
// pressure, the Maxwell relaxation, the rigid needle and the stiffening elastic law. The fourth (fast, 2026-11-28)
// is the default model level: the implicit needle, the kinematic contact, the tissue mass-scaled and stepped
// multi-rate, ellipsoidal supports, and HMB's lip crushed to the scene's depth (0.45 mm then, 0.48 since 2026-11-29).
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cli_run.h"

namespace {

namespace fs = std::filesystem;

std::string file_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The first line where two texts differ (1-based), with both lines, for the failure message.
std::string first_difference(const std::string& a, const std::string& b) {
  std::istringstream sa(a), sb(b);
  std::string la, lb;
  for (int line = 1;; ++line) {
    const bool more_a = static_cast<bool>(std::getline(sa, la)), more_b = static_cast<bool>(std::getline(sb, lb));
    if (!more_a && !more_b) return "identical";
    if (la != lb || more_a != more_b) return "line " + std::to_string(line) + ":\n  stored: " + (more_a ? la : "(end)") + "\n  now:    " + (more_b ? lb : "(end)");
  }
}

void check_repeats(const std::string& name) {
  const fs::path source(NEEDLE_SOURCE_DIR);
  const fs::path out = fs::temp_directory_path() / ("needle_regression_" + name);
  fs::remove_all(out);
  const auto r = needle_test::run("simulate " + (source / "data/scenes/regression" / (name + ".json")).string() + " --out " + out.string() + " --quiet", true);
  INFO(r.out);
  REQUIRE(r.exit_code == 0);
  for (const char* file : {"history.csv", "facet_forces.csv"}) {
    const std::string stored = file_text(source / "tests/data/regression" / name / file), now = file_text(out / file);
    INFO(name << "/" << file << ": " << first_difference(stored, now));
    REQUIRE(!stored.empty());
    CHECK(stored == now);
  }
}

}  // namespace

TEST_CASE("Regression scene: SB into a small block repeats its stored history bit for bit", "[regression][gmsh][slow]") { check_repeats("sb"); }

TEST_CASE("Regression scene: every optional model on (slit, crack, cutting pressure, relaxation) repeats bit for bit", "[regression][gmsh][slow]") {
  check_repeats("models");
}

TEST_CASE("Regression scene: a rigid needle in the stiffening elastic law repeats bit for bit", "[regression][gmsh][slow]") { check_repeats("rigid"); }

TEST_CASE("Regression scene: the default (fast) model level on HMB, its lip crushed, repeats bit for bit", "[regression][gmsh][slow]") {
  check_repeats("fast");
}
