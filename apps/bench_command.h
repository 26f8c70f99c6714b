#pragma once
#include <CLI/CLI.hpp>

namespace needle {
// `needle bench insertion --out DIR`: speed against error of the model levels (studies/speed_error.h).
void add_bench_command(CLI::App& app);
}  // namespace needle
