// `needle`: the toolkit's one command. Each subcommand lives in its own file.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <fmt/format.h>

#include "apps/material_test_command.h"
#include "apps/calibrate_command.h"
#include "apps/mesh_command.h"
#include "apps/paper_command.h"
#include "apps/run_command.h"
#include "apps/simulate_command.h"
#include "apps/stiffness_command.h"
#include "apps/tip_command.h"
#include "core/input_error.h"
#include "core/solver_error.h"

int main(int argc, char** argv) {
  CLI::App app{"needle: design biopsy needle tips - grinding CAD, meshing and insertion simulation"};
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
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const needle::InputError& e) {
    fmt::print(stderr, "needle: error: {}\n", e.what());
    return 2;
  } catch (const needle::SolverError& e) {
    fmt::print(stderr, "needle: the solver stopped: {}\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    fmt::print(stderr, "needle: failed: {}\n", e.what());
    return 1;
  }
  return 0;
}
