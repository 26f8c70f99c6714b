// One writer a folder for every command that writes one (issue 51): while another process holds an output folder's
// lock (runs/writer_lock.h), sweep, stress, optimize, paper and calibrate refuse that --out at once, in one line
// naming the holder's pid, and write nothing into it. (A run's own folder: tests/runs/test_writer_lock.cpp.)
#include <catch2/catch.hpp>
#include <algorithm>
#include <filesystem>
#include <string>
#include <unistd.h>

#include "cli_run.h"
#include "run_fixtures.h"
#include "runs/writer_lock.h"

namespace fs = std::filesystem;
using namespace needle_test;

TEST_CASE("sweep, stress, optimize, paper and calibrate refuse an --out another needle is writing", "[apps]") {
  const fs::path dir = fresh_folder("output_locks");
  const std::string data = std::string(NEEDLE_SOURCE_DIR) + "/data";
  const std::vector<std::pair<std::string, std::string>> commands = {
      {"sweep", "sweep " + data + "/sweeps/d_a_paper.json --jobs 2 --out "},
      {"stress", "stress --short --out "},
      {"optimize", "optimize " + data + "/optimize/straight_d_a.json --out "},
      {"paper", "paper --needles SB --out "},
      {"calibrate", "calibrate --target-deflection-mm -1.14 --out "},
  };
  for (const auto& [name, command] : commands) {
    const fs::path out = dir / name;
    const needle::WriterLock held(out, out.string());  // this test process is the other writer
    // Written with a trailing slash, as a shell's completion gives it: the same folder, the same lock.
    const auto r = run(command + out.string() + "/ --quiet", true);
    INFO(command << ": " << r.out);
    CHECK(r.exit_code == 2);
    CHECK(r.out.find("is being written by another needle (pid " + std::to_string(::getpid()) + ")") != std::string::npos);
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
    CHECK_FALSE(fs::exists(out));
  }
  // The lock let go, the same command may use the folder: a sweep's table from no cases yet is refused for another
  // reason (--collect on a folder without a sweep), not for the lock.
  const auto after = run("sweep " + data + "/sweeps/d_a_paper.json --collect --out " + (dir / "sweep").string(), true);
  INFO(after.out);
  CHECK(after.exit_code == 2);
  CHECK(after.out.find("is being written") == std::string::npos);
  CHECK(after.out.find("holds no sweep") != std::string::npos);
}
