#include "plot/axis_ticks.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

namespace needle {

double nice_tick_step(double span, int target) {
  const double raw = span / target;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * magnitude >= raw) return m * magnitude;
  return 10 * magnitude;
}

std::string tick_label(double value, double step) {
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  if (std::abs(value) < 1e-12 * step) value = 0;
  return fmt::format("{:.{}f}", value, decimals);
}

}  // namespace needle
