// `needle`: the toolkit's one command. Each subcommand lives in its own file.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <new>
#include <fmt/format.h>
#include <sstream>
#include <string>

#include "core/provenance.h"

#include "apps/material_test_command.h"
#include "apps/bench_command.h"
#include "apps/calibrate_command.h"
#include "apps/mesh_command.h"
#include "apps/paper_command.h"
#include "apps/run_command.h"
#include "apps/simulate_command.h"
#include "apps/sweep_command.h"
#include "apps/stress_command.h"
#include "apps/optimize_command.h"
#include "apps/stiffness_command.h"
#include "apps/tip_command.h"
#include "core/input_error.h"
#include "core/interrupt.h"
#include "core/solver_error.h"

namespace {

// A number given on the command line must be finite: options read NaN as "not given", so "--travel-mm nan"
// would otherwise quietly run the default. Every value of every option given (list items split at commas)
// that reads as a number is checked before any command runs.
void refuse_non_finite_numbers(const CLI::App& command) {
  for (const CLI::Option* option : command.get_options()) {
    if (option->count() == 0) continue;
    for (const std::string& result : option->results()) {
      std::stringstream items(result);
      for (std::string item; std::getline(items, item, ',');) {
        char* end = nullptr;
        const double value = std::strtod(item.c_str(), &end);
        const bool whole_number = end != item.c_str() && *end == '\0';
        NEEDLE_REQUIRE(!whole_number || std::isfinite(value),
                       fmt::format("{} {}: give a finite number", option->get_name(false, true), result));
      }
    }
  }
}

// An error as one line of bounded length: a library's message can carry a whole file (assimp echoed 2 MB of a
// broken ASCII STL) or line breaks; the line keeps its first 400 characters and says how many it left out.
std::string one_line(const char* what) {
  constexpr size_t kMaxChars = 400;
  std::string text(what);
  for (char& c : text)
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
  if (text.size() <= kMaxChars) return text;
  return fmt::format("{} ... ({} more characters left out)", text.substr(0, kMaxChars), text.size() - kMaxChars);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"needle: design biopsy needle tips - grinding CAD, meshing and insertion simulation"};
  app.set_version_flag("--version", needle::provenance_line() + "\n" + needle::numerical_libraries_line(), "Print the toolkit's version and the commit it was built from, and exit");
  app.require_subcommand(1);
  needle::add_tip_command(app);
  needle::add_mesh_command(app);
  needle::add_particles_command(app);
  needle::add_material_test_command(app);
  needle::add_stiffness_command(app);
  needle::add_simulate_command(app);
  needle::add_run_command(app);
  needle::add_paper_command(app);
  needle::add_calibrate_command(app);
  needle::add_bench_command(app);
  needle::add_sweep_command(app);
  needle::add_optimize_command(app);
  needle::add_stress_command(app);
  for (CLI::App* command : app.get_subcommands({})) command->parse_complete_callback([command] { refuse_non_finite_numbers(*command); });
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help: the help text, exit 0
  } catch (const CLI::ParseError& e) {
    // A flag the command does not know, a value that does not convert, a required flag missing: the project's one line.
    fmt::print(stderr, "needle: error: {} (--help lists the flags)\n", one_line(e.what()));
    return 2;
  } catch (const needle::InputError& e) {
    fmt::print(stderr, "needle: error: {}\n", one_line(e.what()));
    return 2;
  } catch (const needle::Interrupted& e) {
    fmt::print(stderr, "needle: {}\n", one_line(e.what()));
    return 128 + e.signal;
  } catch (const needle::SolverError& e) {
    fmt::print(stderr, "needle: the solver stopped: {}\n", one_line(e.what()));
    return 3;
  } catch (const needle::StudyIncomplete& e) {
    fmt::print(stderr, "needle: {}\n", one_line(e.what()));
    return 3;
  } catch (const needle::PassedExitStatus& e) {
    return e.code;
  } catch (const std::filesystem::filesystem_error& e) {
    // The environment, not the input: a folder that cannot be made or written, a disk that is full.
    fmt::print(stderr, "needle: cannot read or write a file: {}\n", one_line(e.what()));
    return 4;
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "needle: out of memory\n");
    return 4;
  } catch (const std::exception& e) {
    fmt::print(stderr, "needle: failed: {}\n", one_line(e.what()));
    return 1;
  }
  return 0;
}
