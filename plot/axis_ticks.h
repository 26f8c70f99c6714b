#pragma once
// Axis ticks shared by the charts: spacing 1, 2 or 5 x 10^k and labels with just enough decimals.
#include <string>

namespace needle {

// Tick spacing giving about `target` intervals over span.
double nice_tick_step(double span, int target);
// The value printed with the decimals the step needs (no "-0").
std::string tick_label(double value, double step);

}  // namespace needle
