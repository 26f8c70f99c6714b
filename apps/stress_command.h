#pragma once
#include <CLI/CLI.hpp>

namespace needle {
// `needle stress --out DIR`: the hard-case suite (data/stress/): about twenty corners of the parameter space, each run
// to its end or to the monitor that stops it, and the table that says which.
void add_stress_command(CLI::App& app);
}  // namespace needle
