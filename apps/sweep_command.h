#pragma once
#include <CLI/CLI.hpp>

namespace needle {
// `needle sweep FILE --out DIR`: a design sweep on worker processes, MPI ranks or a batch array, and its table.
void add_sweep_command(CLI::App& app);
}  // namespace needle
