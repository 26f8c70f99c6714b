#pragma once
#include <CLI/CLI.hpp>

namespace needle {
// `needle run --preset SB --out DIR`: the whole chain CAD -> mesh -> particles -> coupled insertion.
void add_run_command(CLI::App& app);
}  // namespace needle
