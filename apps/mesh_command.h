#pragma once
#include <CLI/CLI.hpp>

namespace needle {
// `needle mesh`: gmsh tet mesh (T4/T10) of a tip or of a surface file, with a quality report.
void add_mesh_command(CLI::App& app);
// `needle particles`: tissue particle lattice, optionally classified against a needle.
void add_particles_command(CLI::App& app);
}  // namespace needle
