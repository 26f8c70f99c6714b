// The implicit needle's results do not depend on the BLAS the machine selects (issue 51): CHOLMOD calls
// libblas.so.3, which Debian's alternatives (or LD_LIBRARY_PATH) may point at ATLAS or OpenBLAS, and the same binary
// then gave SB other last digits. The build links the reference BLAS and LAPACK by path through the executables'
// RPATH (solver/CMakeLists.txt); here a short SB insertion runs with another BLAS first on the library path and must
// give the same bits, and every run records the BLAS it loaded.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_run.h"
#include "run_fixtures.h"

namespace fs = std::filesystem;
using namespace needle_test;

namespace {

// SB pushed 4 mm into a small block (6 x 4 x 1.6 mm: the run is short, and ATLAS still moved its deflection in the
// eighth digit, -0.1025458 against -0.1025505 mm) with the default model (the implicit needle, factorised by CHOLMOD),
// with `environment` ahead of the command; the run's summary.
nlohmann::json short_sb_run(const std::string& name, const std::string& environment) {
  const fs::path dir = fresh_folder(name);
  const auto r = shell(environment + " " + std::string(NEEDLE_BINARY) + " run --preset SB --travel-mm 4 --tissue-size-mm 6,4,1.6 --frames 0 --threads 1 --quiet --out " +
                       (dir / "run").string() + " 2>&1");
  INFO(r.out);
  REQUIRE(r.exit_code == 0);
  std::ifstream file(dir / "run" / "summary.json");
  return nlohmann::json::parse(file);
}

// Folders holding another BLAS's libblas.so.3 (Debian's ATLAS, OpenBLAS or BLIS packages), or the one
// NEEDLE_TEST_OTHER_BLAS_DIR names.
std::vector<fs::path> other_blas_folders(const fs::path& multiarch_lib) {
  std::vector<fs::path> found;
  if (const char* dir = std::getenv("NEEDLE_TEST_OTHER_BLAS_DIR")) found.emplace_back(dir);
  for (const char* name : {"atlas", "openblas-pthread", "openblas-openmp", "openblas-serial", "blis-pthread", "blis-openmp", "blis-serial"})
    if (fs::exists(multiarch_lib / name / "libblas.so.3")) found.push_back(multiarch_lib / name);
  return found;
}

}  // namespace

TEST_CASE("needle --version names the BLAS and LAPACK it loaded: the reference ones", "[apps]") {
  const auto version = run("--version");
  REQUIRE(version.exit_code == 0);
  INFO(version.out);
  CHECK(version.out.find("\nBLAS /") != std::string::npos);
  CHECK(version.out.find("/blas/libblas.so") != std::string::npos);
  CHECK(version.out.find("/lapack/liblapack.so") != std::string::npos);
}

TEST_CASE("the implicit needle gives the same bits with another BLAS first on the library path", "[apps][lspg][gmsh][slow]") {
  const nlohmann::json reference = short_sb_run("blas_reference", "");
  const std::string blas = reference["provenance"]["blas"];
  INFO("loaded: " << blas);
  REQUIRE(blas.find("/blas/libblas.so") != std::string::npos);
  CHECK(reference["provenance"]["lapack"].get<std::string>().find("/lapack/liblapack.so") != std::string::npos);
  CHECK(reference["needle_factorizations"].get<int>() >= 1);
  const fs::path multiarch_lib = fs::path(blas).parent_path().parent_path();
  const std::vector<fs::path> others = other_blas_folders(multiarch_lib);
  INFO("scripts/install-deps.sh installs ATLAS (libatlas3-base) for this test");
  REQUIRE(!others.empty());
  for (const fs::path& other : others) {
    INFO("LD_LIBRARY_PATH=" << other.string());
    // The other BLAS's own folder first, then the folder of what it needs (ATLAS's libatlas.so.3), as its package lays them out.
    const nlohmann::json summary =
        short_sb_run("blas_other", "LD_LIBRARY_PATH=" + other.string() + ":" + other.parent_path().string() + ":" + multiarch_lib.string());
    CHECK(summary["provenance"]["blas"] == blas);
    CHECK(summary["provenance"]["lapack"] == reference["provenance"]["lapack"]);
    CHECK(summary["deflection_mm"].get<double>() == reference["deflection_mm"].get<double>());
    CHECK(summary["tip_displacement_mm"] == reference["tip_displacement_mm"]);
  }
}
