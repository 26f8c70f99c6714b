// Design sweeps and optimisation (sweeps/): the cases a sweep file makes (grid and Latin hypercube against their
// definitions), where the deflection crosses zero (against the straight line through two cases), one tiny sweep run
// on worker processes, on MPI ranks and as a batch array with the same table, a sweep interrupted and started again,
// bad files refused before anything runs, and `needle optimize` with its best tip read back by `needle tip`.
#include <catch2/catch.hpp>
#include <regex>
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "../apps/cli_run.h"
#include "../apps/run_fixtures.h"
#include "core/input_error.h"
#include "runs/csv_table.h"
#include "sweeps/sweep_plan.h"
#include "sweeps/sweep_table.h"

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace needle_test;

namespace {

// The tiny sweep's files (tests/data/sweeps/tiny/, which the Slurm test runs too): a 26 mm multi-bevel tip pushed
// 0.8 mm into the small block, the fast model, a case about a second; the sweep: two d_a (one beyond the rod: a tip
// that cannot be ground) and two frictions, 6 cases, 4 of them run.
void copy_tiny(const fs::path& dir, const char* file) {
  fs::copy_file(fs::path(NEEDLE_SOURCE_DIR) / "tests/data/sweeps/tiny" / file, dir / file, fs::copy_options::overwrite_existing);
}
void write_tiny_scene(const fs::path& dir) { copy_tiny(dir, "scene.json"); }
void write_tiny_sweep(const fs::path& dir) {
  write_tiny_scene(dir);
  copy_tiny(dir, "sweep.json");
}

json read_json(const fs::path& path) {
  std::ifstream in(path);
  REQUIRE(in.good());
  return json::parse(in);
}

// Each case's deflection as written in its record (the exact double), by case name.
std::map<std::string, double> deflections(const fs::path& out) {
  std::map<std::string, double> d;
  const json table = read_json(out / "sweep.json");
  for (const json& c : table["cases"])
    if (c["status"] == "finished") d[c["name"].get<std::string>()] = c["deflection_mm"].get<double>();
  return d;
}

std::string stderr_of(const std::string& command) { return shell("(" + command + ") 2>&1").out; }

}  // namespace

TEST_CASE("A sweep file's grid and Latin hypercube make the cases their definitions give", "[sweeps]") {
  const fs::path dir = fresh_folder("sweep_plan");
  write_tiny_scene(dir);
  write(dir / "grid.json", R"({"base": {"scene": "scene.json"}, "variables": {"tissue.friction": [0.1, 0.2], "d_a_mm": {"from": -0.3, "to": 0.3, "count": 4}}})");
  const needle::SweepPlan grid = needle::read_sweep_file((dir / "grid.json").string());
  REQUIRE(grid.cases.size() == 8);
  CHECK(grid.variables == std::vector<std::string>{"d_a_mm", "tissue.friction"});  // alphabetical, the last fastest
  for (int k = 0; k < 8; ++k) {
    const json& v = grid.cases[k].values;
    CHECK(v["d_a_mm"].get<double>() == Approx(-0.3 + 0.2 * (k / 2)).margin(1e-15));
    CHECK(v["tissue.friction"].get<double>() == (k % 2 == 0 ? 0.1 : 0.2));
    CHECK(grid.cases[k].name == fmt::format("case_{:04d}", k));
  }
  CHECK(grid.cases.back().values["d_a_mm"].get<double>() == 0.3);  // the range's end exactly
  CHECK(grid.cases[2].values["d_a_mm"].get<double>() == -0.1);     // the decimal, not -0.3 + 0.2 in binary

  write(dir / "lhs.json", R"({"base": {"scene": "scene.json"}, "design": {"latin_hypercube": {"samples": 7, "seed": 11}},)"
                          R"("variables": {"d_a_mm": {"from": -0.35, "to": 0.35}, "bevel_tilt_deg": {"from": 10, "to": 14}}})");
  const needle::SweepPlan lhs = needle::read_sweep_file((dir / "lhs.json").string());
  REQUIRE(lhs.cases.size() == 7);
  // One sample in each of the 7 equal strata of each variable's range.
  for (const auto& [name, from, to] : {std::tuple<std::string, double, double>{"d_a_mm", -0.35, 0.35}, {"bevel_tilt_deg", 10.0, 14.0}}) {
    std::set<int> strata;
    for (const needle::SweepCase& c : lhs.cases) {
      const double u = (c.values[name].get<double>() - from) / (to - from);
      CHECK(u >= 0);
      CHECK(u < 1);
      strata.insert(static_cast<int>(u * 7));
    }
    CHECK(strata.size() == 7);
  }
  // The same seed repeats the cases; another seed gives others.
  CHECK(needle::sweep_plan_to_json(needle::read_sweep_file((dir / "lhs.json").string())) == needle::sweep_plan_to_json(lhs));
  write(dir / "lhs2.json", R"({"base": {"scene": "scene.json"}, "design": {"latin_hypercube": {"samples": 7, "seed": 12}},)"
                           R"("variables": {"d_a_mm": {"from": -0.35, "to": 0.35}, "bevel_tilt_deg": {"from": 10, "to": 14}}})");
  CHECK(needle::read_sweep_file((dir / "lhs2.json").string()).cases[0].values != lhs.cases[0].values);
}

TEST_CASE("The deflection's zero crossings lie on the straight line between the two cases around them", "[sweeps]") {
  std::vector<needle::CaseResult> rows;
  const std::vector<std::pair<double, double>> points = {{-0.4, -0.30}, {-0.2, -0.10}, {0.0, 0.15}, {0.2, 0.40}, {0.4, 0.0}};
  for (size_t k = 0; k < points.size(); ++k) {
    needle::CaseResult r;
    r.index = static_cast<int>(k);
    r.values = {{"d_a_mm", points[k].first}};
    r.status = "finished";
    r.deflection_mm = points[k].second;
    rows.push_back(r);
  }
  needle::CaseResult stopped = rows[1];
  const auto zeros = needle::deflection_zeros({"d_a_mm"}, rows);
  REQUIRE(zeros.size() == 2);
  CHECK(zeros[0].value == Approx(-0.2 + 0.2 * 0.10 / 0.25));  // between -0.10 and +0.15
  CHECK(zeros[1].value == 0.4);                               // a case that went straight
  rows[2].status = "stopped";  // a stopped case is no point of the curve: the crossing is between -0.2 and 0.2
  const auto without = needle::deflection_zeros({"d_a_mm"}, rows);
  REQUIRE(without.size() == 2);
  CHECK(without[0].value == Approx(-0.2 + 0.4 * 0.10 / 0.50));
}

TEST_CASE("needle sweep gives one table on worker processes, on MPI ranks and as a batch array", "[sweeps][gmsh][lspg][slow]") {
  const fs::path dir = fresh_folder("sweep_workers");
  write_tiny_sweep(dir);
  const std::string sweep = (dir / "sweep.json").string();
  const Result jobs = run("sweep " + sweep + " --out " + (dir / "jobs").string() + " --jobs 2", true);
  INFO(jobs.out);
  REQUIRE(jobs.exit_code == 0);
  const json table = read_json(dir / "jobs" / "sweep.json");
  CHECK(table["counts"]["cases"] == 6);
  CHECK(table["provenance"]["commit"].is_string());  // the code that wrote the table
  CHECK(table["counts"]["finished"] == 4);
  CHECK(table["counts"]["infeasible"] == 2);
  for (const json& c : table["cases"]) {
    const std::string name = c["name"];
    if (c["variables"]["d_a_mm"].get<double>() == -0.6) {
      CHECK(c["status"] == "infeasible");
      CHECK(c["reason"].get<std::string>().find("outside the rod") != std::string::npos);
      continue;
    }
    REQUIRE(c["status"] == "finished");
    // The record repeats its run's own summary and scene: the case ran with its variables.
    const json summary = read_json(dir / "jobs" / "cases" / name / "run" / "summary.json");
    const json scene = read_json(dir / "jobs" / "cases" / name / "run" / "scene.json");
    CHECK(c["deflection_mm"].get<double>() == summary["deflection_mm"].get<double>());
    CHECK(scene["needle"]["d_a_mm"].get<double>() == c["variables"]["d_a_mm"].get<double>());
    CHECK(scene["tissue"]["friction"].get<double>() == c["variables"]["tissue.friction"].get<double>());
    CHECK(scene["needle"]["model"] == "implicit");
  }
  std::ifstream csv(dir / "jobs" / "sweep.csv");
  int csv_lines = 0;
  for (std::string line; std::getline(csv, line);) ++csv_lines;
  CHECK(csv_lines == 7);  // the header and a row a case (reasons are quoted fields of one line)
  CHECK(fs::exists(dir / "jobs" / "deflection_vs_d_a_mm.png"));
  CHECK(fs::exists(dir / "jobs" / "deflection_map.png"));  // two variables: a map over them
  const auto reference = deflections(dir / "jobs");
  REQUIRE(reference.size() == 4);

  // MPI: rank 0 hands out the cases, rank 1 runs them.
  const std::string mpi = stderr_of("mpirun --allow-run-as-root --oversubscribe -n 2 " + std::string(NEEDLE_BINARY) + " sweep " + sweep + " --out " +
                                    (dir / "mpi").string() + "; echo exit=$?");
  INFO(mpi);
  CHECK(mpi.find("exit=0") != std::string::npos);
  CHECK(mpi.find("on 2 MPI ranks") != std::string::npos);
  CHECK(deflections(dir / "mpi") == reference);  // bit for bit

  // --mpi 2: needle starts mpirun itself (mpirun_launcher.h), the same table bit for bit.
  const Result launched = run("sweep " + sweep + " --out " + (dir / "mpi_launched").string() + " --mpi 2", true);
  INFO(launched.out);
  CHECK(launched.exit_code == 0);
  CHECK(launched.out.find("on 2 MPI ranks") != std::string::npos);
  CHECK(deflections(dir / "mpi_launched") == reference);
  for (const char* flags : {" --mpi 2 --jobs 2", " --mpi 2 --collect"}) {
    const Result bad = run("sweep " + sweep + " --out " + (dir / "mpi_bad").string() + flags, true);
    INFO(flags << ": " << bad.out);
    CHECK(bad.exit_code == 2);
    CHECK(bad.out.find("--mpi runs the whole sweep on MPI ranks") != std::string::npos);
    CHECK(!fs::exists(dir / "mpi_bad"));
  }

  // One rank alone runs the cases itself, and says how long each took (issue 51: it said 0 s for cases of 1.4 s).
  const std::string mpi1 = stderr_of("mpirun --allow-run-as-root --oversubscribe -n 1 " + std::string(NEEDLE_BINARY) + " sweep " + sweep + " --out " +
                                     (dir / "mpi1").string() + "; echo exit=$?");
  INFO(mpi1);
  CHECK(mpi1.find("exit=0") != std::string::npos);
  CHECK(deflections(dir / "mpi1") == reference);
  {
    const std::regex line("sweep: (case_[0-9]+) finished in ([0-9]+) s");
    int timed = 0;
    for (auto it = std::sregex_iterator(mpi1.begin(), mpi1.end(), line); it != std::sregex_iterator(); ++it) {
      std::ifstream in(dir / "mpi1" / "cases" / (*it)[1].str() / "run" / "summary.json");
      REQUIRE(in.good());
      const double runtime_s = nlohmann::json::parse(in)["runtime_s"].get<double>();
      INFO((*it)[0].str() << "; the run's own runtime " << runtime_s << " s");
      CHECK(std::stod((*it)[2].str()) + 0.5 >= runtime_s);  // the case's wall time holds its run's
      ++timed;
    }
    CHECK(timed == 4);
  }

  // A batch array: one case a task (SLURM_ARRAY_TASK_ID), then --collect.
  const Result count = run("sweep " + sweep + " --count");
  REQUIRE(count.exit_code == 0);
  REQUIRE(std::stoi(count.out) == 6);
  for (int task = 0; task < 6; ++task) {
    setenv("SLURM_ARRAY_TASK_ID", std::to_string(task).c_str(), 1);
    const Result r = run("sweep " + sweep + " --out " + (dir / "array").string() + " --quiet", true);
    unsetenv("SLURM_ARRAY_TASK_ID");
    INFO(r.out);
    REQUIRE(r.exit_code == 0);
    CHECK(!fs::exists(dir / "array" / "sweep.csv"));  // a task writes its case, not the table
  }
  const Result collected = run("sweep " + sweep + " --out " + (dir / "array").string() + " --collect", true);
  INFO(collected.out);
  REQUIRE(collected.exit_code == 0);
  CHECK(deflections(dir / "array") == reference);
  const Result missing = run("sweep " + sweep + " --out " + (dir / "nothing").string() + " --collect", true);
  CHECK(missing.exit_code == 2);
  CHECK(!fs::exists(dir / "nothing"));

  // A table whose cases did not all finish is still written, and the sweep exits 3 saying how many did not: here one
  // finished case's record turned into a stopped one (the two infeasible tips are the design's answer, not failures).
  const json table_before = read_json(dir / "array" / "sweep.json");
  for (const json& c : table_before["cases"]) {
    if (c["status"] != "finished") continue;
    const fs::path record = dir / "array" / "cases" / c["name"].get<std::string>() / "case.json";
    json r = read_json(record);
    r["status"] = "stopped";
    r["reason"] = "energy drift (a test's edit)";
    std::ofstream(record) << r.dump(2);
    break;
  }
  const Result incomplete = run("sweep " + sweep + " --out " + (dir / "array").string() + " --collect", true);
  INFO(incomplete.out);
  CHECK(incomplete.exit_code == 3);
  CHECK(incomplete.out.find("needle: 1 of 6 cases did not finish (1 stopped, 0 timed out, 0 failed, 0 not run)") != std::string::npos);
  CHECK(read_json(dir / "array" / "sweep.json")["counts"]["stopped"] == 1);
}

TEST_CASE("A sweep interrupted midway, or whose listed design grows, loses no finished case and repeats none when started again", "[sweeps][gmsh][lspg][slow]") {
  const fs::path dir = fresh_folder("sweep_resume");
  write_tiny_scene(dir);
  write(dir / "sweep.json", R"({"base": {"scene": "scene.json"}, "model": "fast", "variables": {"tissue.friction": {"from": 0.05, "to": 0.4, "count": 8}}})");
  const fs::path out = dir / "out";
  // Started in the background and sent SIGINT once its first case is done.
  const std::string script = std::string(NEEDLE_BINARY) + " sweep " + (dir / "sweep.json").string() + " --out " + out.string() +
                             " --quiet & pid=$!; while [ ! -f " + (out / "cases" / "case_0000" / "case.json").string() +
                             " ]; do sleep 0.05; done; kill -INT $pid; wait $pid; echo exit=$?";
  const std::string first = stderr_of("bash -c '" + script + "'");
  INFO(first);
  CHECK(first.find("exit=130") != std::string::npos);
  CHECK(first.find("the same command goes on from there") != std::string::npos);
  std::map<std::string, fs::file_time_type> done_before;
  for (int k = 0; k < 8; ++k) {
    const fs::path record = out / "cases" / fmt::format("case_{:04d}", k) / "case.json";
    if (fs::exists(record)) done_before[record.string()] = fs::last_write_time(record);
  }
  REQUIRE(!done_before.empty());
  REQUIRE(done_before.size() < 8);
  const Result again = run("sweep " + (dir / "sweep.json").string() + " --out " + out.string(), true);
  INFO(again.out);
  REQUIRE(again.exit_code == 0);
  CHECK(again.out.find(fmt::format("{} of 8 cases done before", done_before.size())) != std::string::npos);
  for (const auto& [record, time] : done_before) CHECK(fs::last_write_time(record) == time);  // not run again
  CHECK(read_json(out / "sweep.json")["counts"]["finished"] == 8);
  // A case whose run was interrupted while stepping (its folder holds what it had, marked interrupted) runs again.
  const fs::path run3 = out / "cases" / "case_0003" / "run";
  json summary3 = read_json(run3 / "summary.json");
  summary3["status"] = "interrupted";
  std::ofstream(run3 / "summary.json") << summary3.dump(2);
  fs::remove(out / "cases" / "case_0003" / "case.json");
  const Result rerun = run("sweep " + (dir / "sweep.json").string() + " --out " + out.string(), true);
  INFO(rerun.out);
  REQUIRE(rerun.exit_code == 0);
  CHECK(rerun.out.find("7 of 8 cases done before") != std::string::npos);
  CHECK(read_json(run3 / "summary.json")["status"] == "finished");
  CHECK(read_json(out / "sweep.json")["counts"]["finished"] == 8);
  // A case recorded finished whose run folder is gone (deleted, or lost to a second writer before the folder locks)
  // is not done: it runs again, and the others are kept (issue 51: "a rerun says 4 of 4 done").
  const fs::path record5 = out / "cases" / "case_0005" / "case.json";
  const auto record5_time = fs::last_write_time(record5);
  fs::remove_all(out / "cases" / "case_0005" / "run");
  const Result lost = run("sweep " + (dir / "sweep.json").string() + " --out " + out.string(), true);
  INFO(lost.out);
  REQUIRE(lost.exit_code == 0);
  CHECK(lost.out.find("7 of 8 cases done before") != std::string::npos);
  CHECK(fs::is_regular_file(out / "cases" / "case_0005" / "run" / "summary.json"));
  CHECK(fs::last_write_time(record5) != record5_time);
  CHECK(read_json(out / "sweep.json")["counts"]["finished"] == 8);
  // The study names the code that began it; another build goes on only when told (issue 51: versions mixed in silence).
  {
    std::ifstream code_in(out / "study_code.txt");
    std::string began;
    std::getline(code_in, began);
    CHECK(began.rfind("needle ", 0) == 0);
    CHECK(began.find("commit") != std::string::npos);
    write(out / "study_code.txt", "needle 0.0.1 (commit 000000000000, Release)\n");
    const Result other_code = run("sweep " + (dir / "sweep.json").string() + " --out " + out.string(), true);
    INFO(other_code.out);
    CHECK(other_code.exit_code == 2);
    CHECK(other_code.out.find("its cases were run by needle 0.0.1 (commit 000000000000, Release); this is " + began) != std::string::npos);
    CHECK(std::count(other_code.out.begin(), other_code.out.end(), '\n') == 1);
    const Result allowed = run("sweep " + (dir / "sweep.json").string() + " --out " + out.string() + " --allow-other-code", true);
    INFO(allowed.out);
    CHECK(allowed.exit_code == 0);
    CHECK(allowed.out.find("8 of 8 cases done before") != std::string::npos);
  }
  // Another sweep into the same folder is refused, the folder untouched.
  write(dir / "other.json", R"({"base": {"scene": "scene.json"}, "variables": {"tissue.friction": [0.3]}})");
  const Result other = run("sweep " + (dir / "other.json").string() + " --out " + out.string(), true);
  CHECK(other.exit_code == 2);
  CHECK(other.out.find("holds another study") != std::string::npos);
  // A listed design that grows at its end (a study's partial batch completed) goes on in the same folder: the cases
  // done keep their records, only the new ones run. One that drops or changes a case is another study.
  const fs::path listed = dir / "listed";
  write(dir / "two.json", R"({"base": {"scene": "scene.json"}, "model": "fast", "design": {"cases": [{"tissue.friction": 0.1}, {"tissue.friction": 0.2}]}})");
  write(dir / "three.json", R"({"base": {"scene": "scene.json"}, "model": "fast", "design": {"cases": [{"tissue.friction": 0.1}, {"tissue.friction": 0.2}, {"tissue.friction": 0.3}]}})");
  write(dir / "changed.json", R"({"base": {"scene": "scene.json"}, "model": "fast", "design": {"cases": [{"tissue.friction": 0.1}, {"tissue.friction": 0.25}, {"tissue.friction": 0.3}]}})");
  const Result two = run("sweep " + (dir / "two.json").string() + " --out " + listed.string(), true);
  INFO(two.out);
  REQUIRE(two.exit_code == 0);
  const auto first_record_time = fs::last_write_time(listed / "cases" / "case_0000" / "case.json");
  const Result three = run("sweep " + (dir / "three.json").string() + " --out " + listed.string(), true);
  INFO(three.out);
  REQUIRE(three.exit_code == 0);
  CHECK(three.out.find("2 of 3 cases done before") != std::string::npos);
  CHECK(fs::last_write_time(listed / "cases" / "case_0000" / "case.json") == first_record_time);
  CHECK(read_json(listed / "sweep.json")["counts"]["finished"] == 3);
  CHECK(read_json(listed / "sweep_plan.json")["cases"].size() == 3);
  for (const char* file : {"two.json", "changed.json"}) {
    const Result refused = run("sweep " + (dir / file).string() + " --out " + listed.string(), true);
    INFO(refused.out);
    CHECK(refused.exit_code == 2);
    CHECK(refused.out.find("holds another study") != std::string::npos);
  }
  CHECK(read_json(listed / "sweep_plan.json")["cases"].size() == 3);
}

TEST_CASE("needle sweep --mpi interrupted exits 130 and leaves no rank running, killed it leaves no job, and its rerun goes on",
          "[sweeps][gmsh][lspg][slow]") {
  // Under `mpirun -n N needle sweep`, Ctrl-C exits 1 (OpenMPI's mpirun, whatever its ranks return); --mpi starts mpirun
  // in a process group of its own and reports the interruption itself (issue 51).
  const fs::path dir = fresh_folder("sweep_mpi_interrupt");
  write_tiny_scene(dir);
  write(dir / "sweep.json", R"({"base": {"scene": "scene.json"}, "model": "fast", "variables": {"tissue.friction": {"from": 0.05, "to": 0.4, "count": 8}}})");
  for (const char* signal : {"INT", "KILL"}) {
    const fs::path out = dir / (std::string("out_") + signal);
    // mpirun and its ranks get a while to go (on a loaded two-core machine mpirun's own teardown takes seconds); the
    // processes still there at the end are listed.
    const std::string left = "pgrep -f -- '^[^ ]*(needle|mpirun|orted) .*" + out.filename().string() + "'";
    const std::string script = std::string(NEEDLE_BINARY) + " sweep " + (dir / "sweep.json").string() + " --out " + out.string() +
                               " --mpi 2 --quiet & pid=$!\nwhile [ ! -f " + (out / "cases" / "case_0000" / "case.json").string() +
                               " ]; do sleep 0.05; done\nkill -" + signal + " $pid; wait $pid; echo exit=$?\n" +
                               "for i in $(seq 300); do n=$(" + left + " | wc -l); [ $n = 0 ] && break; sleep 0.1; done\n" +
                               "echo left=$n; [ $n = 0 ] || ps -o pid,ppid,etimes,args -p \"$(" + left + " | paste -sd,)\"\n";
    write(dir / (std::string("interrupt_") + signal + ".sh"), script);
    const std::string first = stderr_of("bash " + (dir / (std::string("interrupt_") + signal + ".sh")).string() + " 2>&1");
    INFO(signal << ": " << first);
    CHECK(first.find(std::string(signal) == "INT" ? "exit=130" : "exit=137") != std::string::npos);
    if (std::string(signal) == "INT") CHECK(first.find("the same command goes on from there") != std::string::npos);
    CHECK(first.find("left=0") != std::string::npos);  // no mpirun, no rank
    const Result again = run("sweep " + (dir / "sweep.json").string() + " --out " + out.string() + " --mpi 2", true);
    INFO(again.out);
    CHECK(again.exit_code == 0);
    CHECK(read_json(out / "sweep.json")["counts"]["finished"] == 8);
  }
}

TEST_CASE("A sweep killed by SIGKILL leaves no worker running, and its rerun finishes every case with none failed", "[sweeps][gmsh][lspg][slow]") {
  const fs::path dir = fresh_folder("sweep_sigkill");
  write_tiny_scene(dir);
  // Cases of about 15 s each (a slow drive): without the parent's death signal the workers would still be running 5 s
  // after the parent is killed; with it they stop within the step (or the model's build) they are in.
  write(dir / "sweep.json", R"({"base": {"scene": "scene.json"}, "model": "fast", "set": {"motion.travel_mm": 3, "motion.speed_m_per_s": 1},)"
                            R"("variables": {"tissue.friction": [0.1, 0.2]}})");
  const fs::path out = dir / "out";
  const std::string workers = "pgrep -f -- '--out " + out.string() + " --task-index' | wc -l";
  const std::string script = std::string(NEEDLE_BINARY) + " sweep " + (dir / "sweep.json").string() + " --out " + out.string() +
                             " --jobs 2 --quiet & pid=$!; while [ ! -f " + (out / "cases" / "case_0001" / "worker.log").string() +
                             " ]; do sleep 0.05; done; sleep 0.3; echo running=$(" + workers + "); kill -KILL $pid; for i in $(seq 50); do n=$(" + workers + "); [ $n = 0 ] && break; sleep 0.1; done; echo left=$n";
  write(dir / "kill.sh", script);
  const std::string first = stderr_of("bash " + (dir / "kill.sh").string());
  INFO(first);
  CHECK(first.find("running=0") == std::string::npos);  // the workers were running when the parent died
  CHECK(first.find("left=0") != std::string::npos);     // and none outlived it
  const Result again = run("sweep " + (dir / "sweep.json").string() + " --out " + out.string(), true);
  INFO(again.out);
  REQUIRE(again.exit_code == 0);
  const json table = read_json(out / "sweep.json");
  CHECK(table["counts"]["finished"] == 2);
  CHECK(table["counts"]["failed"] == 0);
}

TEST_CASE("Bad sweep and optimisation files get one clear error before any case runs", "[sweeps][slow]") {
  const fs::path dir = fresh_folder("sweep_bad");
  write_tiny_scene(dir);
  const std::vector<std::pair<std::string, std::string>> sweeps = {
      {R"({"base": {"scene": "scene.json"}, "variables": {"tip_angle": [1, 2]}})", "unknown design variable 'tip_angle'"},
      {R"({"base": {"scene": "scene.json"}, "variables": {"d_a_mm": []}})", "'d_a_mm' is an empty list"},
      {R"({"base": {"scene": "scene.json"}, "variables": {"d_a_mm": {"from": 0.1, "to": 0.1, "count": 3}}})", "the range of 'd_a_mm' is empty"},
      {R"({"base": {"scene": "scene.json"}, "variables": {"d_a_mm": {"from": 0, "to": 0.3, "count": 0}}})", "'count' must be a whole number"},
      {R"({"base": {"scene": "scene.json"}, "variables": {"d_a_mm": {"from": 0, "to": 0.3}}})", "needs 'count'"},
      {R"({"base": {"scene": "scene.json"}, "variabels": {"d_a_mm": [0]}})", "unknown key 'variabels'"},
      {R"({"base": {"scene": "scene.json"}, "variables": {"d_a_mm": [0.7, 0.9]}})", "no case of the sweep has a tip that can be ground"},
      {R"({"base": {"scene": "scene.json"}, "variables": {"tissue.colour": [1, 2]}})", "colour"},
      {R"({"base": {"scene": "scene.json"}, "design": {"latin_hypercube": {"samples": 4}}, "variables": {"d_a_mm": [0, 0.1]}})",
       "a Latin hypercube samples ranges"},
      // The same value twice would run one case twice; a d_a_mm variable would replace a base preset in silence (issue 51).
      {R"({"base": {"scene": "scene.json"}, "variables": {"d_a_mm": [0, 0.1, 0.0]}})", "'d_a_mm' lists 0.0 twice: give each value once"},
      {R"({"base": {"scene": "scene.json"}, "variables": {"tissue.friction": [0.1, 0.2, 0.1]}})", "'tissue.friction' lists 0.1 twice"},
      {R"({"base": {"scene": "scene.json", "preset": "SB"}, "variables": {"d_a_mm": [0, 0.1]}})",
       "a 'd_a_mm' variable grinds the paper's multi-bevel tips, which would replace the base's preset SB"},
      // A spacing no case could run is the scene reader's to refuse, before any case, as `run --set` does (issue 51).
      {R"({"base": {"scene": "scene.json"}, "variables": {"tissue.spacing_mm": [0.4, 1e-5]}})", "would make up to"},
  };
  for (const auto& [text, message] : sweeps) {
    write(dir / "bad.json", text);
    const Result r = run("sweep " + (dir / "bad.json").string() + " --out " + (dir / "out").string(), true);
    INFO(text << "\n" << r.out);
    CHECK(r.exit_code == 2);
    CHECK(r.out.find(message) != std::string::npos);
    CHECK(r.out.find("bad.json") != std::string::npos);
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
    CHECK(!fs::exists(dir / "out"));
  }
  const std::vector<std::pair<std::string, std::string>> searches = {
      {R"({"base": {"scene": "scene.json"}, "variables": {"d_a_mm": {"min": 0.3, "max": -0.3}}, "objective": {"deflection_target_mm": 0}})",
       "contradict each other"},
      {R"({"base": {"scene": "scene.json"}, "variables": {"d_a_mm": {"min": -0.6, "max": 0.3}}, "objective": {"deflection_target_mm": 0}})",
       "cannot be ground"},
      {R"({"base": {"scene": "scene.json"}, "variables": {"d_a_mm": {"min": -0.3, "max": 0.3}}, "objective": {"minimize": "abs_deflection", "groove_fill_at_least": 0.5}, "method": "bobyqa"})",
       "needs method cobyla"},
      {R"({"base": {"scene": "scene.json"}, "variables": {"d_a_mm": {"min": -0.3, "max": 0.3}}, "objective": {"minimize": "abs_deflection", "sample_length_at_least_mm": 5}})",
       "sample_length_at_least_mm needs the sample, which the runs take only when they fire the cannula"},
      {R"({"base": {"scene": "scene.json"}, "set": {"cannula.firing.enabled": true}, "variables": {"d_a_mm": {"min": -0.3, "max": 0.3}}, "objective": {"minimize": "abs_deflection", "sample_length_at_least_mm": -1}})",
       "sample_length_at_least_mm must be positive"},
      {R"({"base": {"scene": "scene.json"}, "variables": {"d_a_mm": {"min": -0.3, "max": 0.3, "start": 0.5}}, "objective": {"deflection_target_mm": 0}})",
       "outside"},
  };
  {
    // An --out that is a file: one line, no progress line before it (issue 51).
    write(dir / "good_search.json", R"({"base": {"scene": "scene.json"}, "variables": {"d_a_mm": {"min": -0.3, "max": 0.3}}, )"
                                    R"("objective": {"deflection_target_mm": 0}})");
    write(dir / "a_file", "x");
    const Result r = run("optimize " + (dir / "good_search.json").string() + " --out " + (dir / "a_file").string(), true);
    INFO(r.out);
    CHECK(r.exit_code == 2);
    CHECK(r.out.find("exists and is not a folder") != std::string::npos);
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
  }
  {
    // The refusal of a negative time limit and --help name the same defaults (issue 51).
    const Result bad = run("stress --short --case-time-limit-s -1 --out " + (dir / "out").string(), true);
    const Result help = run("stress --help", true);
    INFO(bad.out << "\n" << help.out);
    CHECK(bad.exit_code == 2);
    CHECK(bad.out.find("0 for the suite's default (900 s; 120 s with --short)") != std::string::npos);
    CHECK(help.out.find("0: the suite's default, 900 s; 120 s with --short") != std::string::npos);
    CHECK(!fs::exists(dir / "out"));
  }
  for (const auto& [text, message] : searches) {
    write(dir / "bad_search.json", text);
    const Result r = run("optimize " + (dir / "bad_search.json").string() + " --out " + (dir / "out").string(), true);
    INFO(text << "\n" << r.out);
    CHECK(r.exit_code == 2);
    CHECK(r.out.find(message) != std::string::npos);
    CHECK(!fs::exists(dir / "out"));
  }
}

TEST_CASE("needle optimize reaches a deflection target and resumes from its evaluations, a case's tip angles make its recipe",
          "[sweeps][gmsh][lspg][slow]") {
  const fs::path dir = fresh_folder("optimize");
  write_tiny_scene(dir);
  // The tissue's E that makes the tiny scene's tip deflect 0.018 mm (0.0177 mm at E 0.5, 0.0185 mm at 0.7, with the crushed lip).
  write(dir / "search.json", R"({"base": {"scene": "scene.json", "d_a_mm": 0.1}, "model": "fast",)"
                             R"("variables": {"tissue.material.E_MPa": {"min": 0.2, "max": 1.2, "start": 0.7, "step": 0.2, "tolerance": 0.005}},)"
                             R"("objective": {"deflection_target_mm": 0.018}, "deflection_tolerance_mm": 0.0002, "max_evaluations": 10})");
  // The same search with NLopt's BOBYQA on (delta - t)^2 instead of the bracketing root finder (the default for one
  // variable and a target).
  // It starts below the target and steps 0.1 (four evaluations): delta flattens above E 0.7 (0.0187 mm at 0.9 with the
  // tissue multi-rate), and from 0.5, 0.7 and 0.9 the quadratic model of (delta - t)^2 put its minimum below 0.5.
  std::string bobyqa_text = R"({"base": {"scene": "scene.json", "d_a_mm": 0.1}, "model": "fast", "method": "bobyqa",)"
                            R"("variables": {"tissue.material.E_MPa": {"min": 0.2, "max": 1.2, "start": 0.4, "step": 0.1, "tolerance": 0.005}},)"
                            R"("objective": {"deflection_target_mm": 0.018}, "deflection_tolerance_mm": 0.0002, "max_evaluations": 10})";
  write(dir / "bobyqa.json", bobyqa_text);
  const Result bobyqa = run("optimize " + (dir / "bobyqa.json").string() + " --out " + (dir / "bobyqa").string(), true);
  INFO(bobyqa.out);
  REQUIRE(bobyqa.exit_code == 0);
  const json bobyqa_optimum = read_json(dir / "bobyqa" / "optimum.json");
  CHECK(bobyqa_optimum["method"] == "bobyqa");
  CHECK(std::abs(bobyqa_optimum["best"]["deflection_mm"].get<double>() - 0.018) <= 0.0002);

  const std::string args = "optimize " + (dir / "search.json").string() + " --out " + (dir / "out").string();
  const Result first = run(args, true);
  INFO(first.out);
  REQUIRE(first.exit_code == 0);
  const needle::CsvTable evaluations = needle::read_csv_table((dir / "out" / "evaluations.csv").string());
  REQUIRE(evaluations.rows.size() >= 3);
  CHECK(evaluations.rows.size() <= 10);
  const json optimum = read_json(dir / "out" / "optimum.json");
  CHECK(optimum["method"] == "toms748");
  CHECK(optimum["converged"] == true);
  CHECK(std::abs(optimum["best"]["deflection_mm"].get<double>() - 0.018) <= 0.0002);
  // The reported best is the smallest objective among the evaluations, recomputed here from their deflections; each
  // evaluation's run took its E.
  double best = INFINITY;
  for (const auto& row : evaluations.rows) {
    const double delta = row[evaluations.index("deflection_mm")];
    CHECK(row[evaluations.index("objective")] == Approx((delta - 0.018) * (delta - 0.018)).epsilon(1e-8));
    best = std::min(best, (delta - 0.018) * (delta - 0.018));
  }
  CHECK(optimum["best"]["objective"].get<double>() == Approx(best).epsilon(1e-8));
  const std::string best_name = optimum["best"]["name"];
  CHECK(read_json(dir / "out" / "cases" / best_name / "run" / "scene.json")["tissue"]["material"]["E_MPa"].get<double>() ==
        optimum["best"]["variables"]["tissue.material.E_MPa"].get<double>());
  // Started again, the search repeats NLopt's steps from the evaluations already done.
  const Result again = run(args, true);
  INFO(again.out);
  REQUIRE(again.exit_code == 0);
  CHECK(again.out.find("(done before: reused)") != std::string::npos);
  CHECK(read_json(dir / "out" / "optimum.json")["best"] == optimum["best"]);
  CHECK(needle::read_csv_table((dir / "out" / "evaluations.csv").string()).rows.size() == evaluations.rows.size());

  // A case that varies the tip's angles runs a recipe of its own, which needle tip builds with those angles.
  write(dir / "angles.json", R"({"base": {"scene": "scene.json", "d_a_mm": 0.1}, "model": "fast", "variables": {"top_tilt_deg": [20]}})");
  const Result angles = run("sweep " + (dir / "angles.json").string() + " --out " + (dir / "angles").string(), true);
  INFO(angles.out);
  REQUIRE(angles.exit_code == 0);
  const fs::path recipe = dir / "angles" / "cases" / "case_0000" / "recipe.json";
  CHECK(read_json(dir / "angles" / "cases" / "case_0000" / "run" / "scene.json")["needle"]["recipe"] == recipe.string());
  const Result tip = run("tip --recipe " + recipe.string() + " --json");
  REQUIRE(tip.exit_code == 0);
  const json report = json::parse(tip.out);
  CHECK(report["d_a_mm"].get<double>() == Approx(0.1).margin(1e-6));
  int top_facets = 0;
  for (const json& f : report["facets"])
    if (f["name"] == "top") {
      ++top_facets;
      CHECK(f["tilt_deg"].get<double>() == 20.0);
    }
  CHECK(top_facets == 1);
}

TEST_CASE("A sweep with the cannula fired tabulates and plots the sample's length, a search takes it as a constraint",
          "[sweeps][gmsh][lspg][cannula][slow]") {
  // The tiny scene pushed 4.2 mm, so that 1.2 mm of the groove (3 mm behind tip point A) lies in the tissue, with the
  // cannula fired: two d_a in a sweep, then a search for the smallest |delta| whose sample is at least 0.4 mm long.
  const fs::path dir = fresh_folder("sweep_sample");
  write(dir / "scene.json", R"({"needle": {"d_a_mm": 0, "length_mm": 26, "mesh": {"order": 1, "size_mm": 0.5}},)"
                            R"("motion": {"accel_time_ms": 0.02, "travel_mm": 4.2}, "cannula": {"enabled": false, "firing": {"enabled": true}},)"
                            R"("tissue": {"enabled": true, "size_mm": [5, 2.4, 1.2], "spacing_mm": 0.4}, "output": {"frames": 0}})");
  write(dir / "sweep.json", R"({"base": {"scene": "scene.json"}, "model": "fast", "variables": {"d_a_mm": [-0.3, 0.3]}})");
  const Result sweep = run("sweep " + (dir / "sweep.json").string() + " --out " + (dir / "sweep").string(), true);
  INFO(sweep.out);
  REQUIRE(sweep.exit_code == 0);
  CHECK(sweep.out.find("I_s") != std::string::npos);  // the progress lines say it
  const needle::CsvTable table = needle::read_csv_table((dir / "sweep" / "sweep.csv").string());
  REQUIRE(table.rows.size() == 2);
  for (size_t k = 0; k < 2; ++k) {
    const json summary = read_json(dir / "sweep" / "cases" / fmt::format("case_{:04d}", k) / "run" / "summary.json");
    CHECK(table.rows[k][table.index("sample_I_s_mm")] == summary["sample"]["I_s_mm"].get<double>());
  }
  CHECK(fs::exists(dir / "sweep" / "sample_length_vs_d_a_mm.png"));
  // One case alone, as a worker, a batch array's task or an MPI rank runs it: its line says I_s too.
  const Result task = run("sweep " + (dir / "sweep.json").string() + " --out " + (dir / "task").string() + " --task-index 1", true);
  INFO(task.out);
  REQUIRE(task.exit_code == 0);
  CHECK(task.out.find("I_s") != std::string::npos);

  write(dir / "search.json", R"({"base": {"scene": "scene.json"}, "model": "fast",)"
                             R"("variables": {"d_a_mm": {"min": -0.3, "max": 0.3, "start": 0.0, "step": 0.2, "tolerance": 0.02}},)"
                             R"("objective": {"minimize": "abs_deflection", "sample_length_at_least_mm": 0.4}, "max_evaluations": 4})");
  const Result search = run("optimize " + (dir / "search.json").string() + " --out " + (dir / "search").string(), true);
  INFO(search.out);
  REQUIRE(search.exit_code == 0);
  const json optimum = read_json(dir / "search" / "optimum.json");
  CHECK(optimum["method"] == "cobyla");
  REQUIRE(optimum.contains("best"));
  const double best_I_s = optimum["best"]["sample_I_s_mm"].get<double>();
  CHECK(optimum["best"]["meets_sample_length"] == (best_I_s >= 0.4));
  const size_t best_line = search.out.find("optimize: best");  // the best's line says its sample length too
  REQUIRE(best_line != std::string::npos);
  const std::string best_words = search.out.substr(best_line, search.out.find('\n', best_line) - best_line);
  CHECK(best_words.find(fmt::format("I_s {:.2f} mm", best_I_s)) != std::string::npos);
  const needle::CsvTable evaluations = needle::read_csv_table((dir / "search" / "evaluations.csv").string());
  CHECK_NOTHROW(evaluations.index("sample_I_s_mm"));
  const Result tip = run("tip --recipe " + (dir / "search" / "best_recipe.json").string() + " --json");
  CHECK(tip.exit_code == 0);
}

TEST_CASE("Explicit cases set only their own variables and keep their labels", "[sweeps]") {
  const fs::path dir = fresh_folder("sweep_cases");
  write_tiny_scene(dir);
  write(dir / "cases.json", R"({"base": {"scene": "scene.json"}, "set": {"tissue.friction": 0.3}, "design": {"cases": [)"
                            R"({"label": "stiff", "tissue.material.E_MPa": 5}, {"label": "sharp", "d_a_mm": -0.4}, {"tissue.friction": 0.1}]}})");
  const needle::SweepPlan plan = needle::read_sweep_file((dir / "cases.json").string());
  REQUIRE(plan.cases.size() == 3);
  CHECK(plan.design == "cases");
  CHECK(plan.variables == std::vector<std::string>{"d_a_mm", "tissue.friction", "tissue.material.E_MPa"});
  CHECK(plan.cases[0].label == "stiff");
  CHECK(plan.cases[0].values == json{{"tissue.material.E_MPa", 5}});
  // Each case's scene: its own variable over the base and the fixed keys, a case's key over a fixed one.
  const needle::Scene stiff = needle::case_setup(plan.base, plan.cases[0].values).scene;
  const needle::Scene sharp = needle::case_setup(plan.base, plan.cases[1].values).scene;
  const needle::Scene smooth = needle::case_setup(plan.base, plan.cases[2].values).scene;
  CHECK(stiff.tissue.material.E_MPa == 5);
  CHECK(stiff.tissue.friction == 0.3);
  CHECK(sharp.needle.d_a_mm == -0.4);
  CHECK(sharp.tissue.material.E_MPa == smooth.tissue.material.E_MPa);
  CHECK(smooth.tissue.friction == 0.1);
  write(dir / "bad.json", R"({"base": {"scene": "scene.json"}, "design": {"cases": [{"label": 3}]}})");
  CHECK_THROWS_WITH(needle::read_sweep_file((dir / "bad.json").string()), Catch::Contains("'label' must be a string"));
}

TEST_CASE("needle stress runs the short hard-case suite: each case finished with finite numbers or stopped by a monitor",
          "[sweeps][gmsh][lspg][slow]") {
  const fs::path dir = fresh_folder("stress");
  const Result r = run("stress --short --out " + (dir / "out").string(), true);
  INFO(r.out);
  REQUIRE(r.exit_code == 0);
  const json table = read_json(dir / "out" / "sweep.json");
  REQUIRE(table["cases"].size() == 6);
  for (const json& c : table["cases"]) {
    INFO(c.dump());
    CHECK(!c["label"].get<std::string>().empty());
    const bool finished = c["status"] == "finished", stopped = c["status"] == "stopped";
    CHECK((finished || stopped));
    if (finished) {
      CHECK(std::isfinite(c["deflection_mm"].get<double>()));
      CHECK(c["max_energy_balance_error"].get<double>() < 0.05);  // the run's own stop limit
    } else {
      CHECK(!c["reason"].get<std::string>().empty());
    }
  }
  std::ifstream report(dir / "out" / "stress.md");
  const std::string text((std::istreambuf_iterator<char>(report)), std::istreambuf_iterator<char>());
  CHECK(text.find("6 of 6 cases pass; 0 finding(s).") != std::string::npos);
  CHECK(text.find("| very soft tissue (E 0.001 MPa) |") != std::string::npos);

  // A case that outlives the time limit is stopped, recorded as timed out, and is a finding (exit 1).
  write(dir / "slow.json", "{\"base\": {\"scene\": \"" + (fs::path(NEEDLE_SOURCE_DIR) / "data" / "stress" / "stress_scene.json").string() +
                               "\"}, \"model\": \"fast\", \"design\": {\"cases\": [{\"label\": \"slow\", \"motion.travel_mm\": 20}]}}");
  const Result slow = run("stress --suite " + (dir / "slow.json").string() + " --case-time-limit-s 1 --out " + (dir / "slow").string(), true);
  INFO(slow.out);
  CHECK(slow.exit_code == 1);
  CHECK(slow.out.find("1 finding(s)") != std::string::npos);
  const json slow_table = read_json(dir / "slow" / "sweep.json");
  CHECK(slow_table["cases"][0]["status"] == "timed_out");
  CHECK(slow_table["cases"][0]["reason"].get<std::string>().find("time limit") != std::string::npos);
}
