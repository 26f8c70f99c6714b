#pragma once
#include <CLI/CLI.hpp>

namespace needle {
// `needle stiffness`: tip compliance and first bending frequencies of a needle clamped behind its tip.
void add_stiffness_command(CLI::App& app);
}  // namespace needle
