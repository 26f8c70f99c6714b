#pragma once
#include <CLI/CLI.hpp>

namespace needle {
// `needle tip`: build a tip from a preset, a d_a or a recipe file; report, export, render; or
// analyse an existing STL/OBJ/PLY/glTF tip.
void add_tip_command(CLI::App& app);
}
