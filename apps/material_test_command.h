#pragma once
#include <CLI/CLI.hpp>

namespace needle {
// `needle material-test`: the tissue card through a uniaxial tension test on a particle specimen.
void add_material_test_command(CLI::App& app);
}  // namespace needle
