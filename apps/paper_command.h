#pragma once
#include <CLI/CLI.hpp>

namespace needle {
// `needle paper --out DIR`: the paper's four needles on the paper's scene, and the report (paper_report.h).
void add_paper_command(CLI::App& app);
}  // namespace needle
