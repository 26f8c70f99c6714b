#pragma once
#include <CLI/CLI.hpp>

namespace needle {
// `needle optimize FILE --out DIR`: a derivative-free search (NLopt) for the best tip; writes its evaluations and best recipe.
void add_optimize_command(CLI::App& app);
}  // namespace needle
