#pragma once
#include <CLI/CLI.hpp>

namespace needle {
// `needle simulate SCENE --out DIR`: runs a scene and writes a run folder.
void add_simulate_command(CLI::App& app);
}  // namespace needle
