#pragma once
#include <CLI/CLI.hpp>

namespace needle {
// `needle calibrate --preset SB --target-deflection-mm -1.14 --out DIR`: the tissue's E that makes one
// needle deflect as measured, by secant iteration on full runs.
void add_calibrate_command(CLI::App& app);
}  // namespace needle
