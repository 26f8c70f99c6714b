#include "solver/needle/beam_reference.h"

#include <algorithm>
#include <cmath>

#include "core/input_error.h"

namespace needle {

double cantilever_compliance_mm_per_N(const std::function<double(double)>& I, double E, double clamp_x, double load_x,
                                      double point_x, std::vector<double> breakpoints, double step_mm) {
  NEEDLE_REQUIRE(E > 0 && step_mm > 0, "beam reference: E and the step must be positive");
  const double end = std::min(load_x, point_x);
  NEEDLE_REQUIRE(end > clamp_x, "beam reference: the load and the point must lie ahead of the clamp");
  breakpoints.push_back(clamp_x);
  breakpoints.push_back(end);
  std::sort(breakpoints.begin(), breakpoints.end());
  auto integrand = [&](double x) { return (load_x - x) * (point_x - x) / (E * I(x)); };
  double total = 0;
  for (size_t k = 0; k + 1 < breakpoints.size(); ++k) {
    const double a = std::max(breakpoints[k], clamp_x), b = std::min(breakpoints[k + 1], end);
    if (!(b > a)) continue;
    // Open-ended at the pieces' ends (a section exactly at a jump is ambiguous): Simpson on points
    // nudged inside by 1e-9 mm.
    const int n = 2 * std::max(1, static_cast<int>(std::ceil((b - a) / step_mm / 2)));
    const double h = (b - a) / n;
    double sum = 0;
    for (int i = 0; i <= n; ++i) {
      const double x = std::clamp(a + i * h, a + 1e-9, b - 1e-9);
      sum += (i == 0 || i == n ? 1.0 : (i % 2 ? 4.0 : 2.0)) * integrand(x);
    }
    total += sum * h / 3.0;
  }
  return total;
}

}  // namespace needle
