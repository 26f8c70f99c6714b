#include "sweeps/target_bracket.h"

#include <algorithm>
#include <boost/math/tools/toms748_solve.hpp>
#include <cmath>
#include <fmt/format.h>
#include <map>

namespace needle {

TargetBracket bracket_target(const std::function<double(double)>& miss, const std::string& variable, double lo, double hi, double x_tolerance,
                             double deflection_tolerance_mm, int max_evaluations) {
  TargetBracket out;
  out.from = out.to = std::nan("");
  const bool tolerance_given = std::isfinite(deflection_tolerance_mm);
  struct CloseEnough {
    double x, miss;
  };
  std::map<double, double> misses;  // every evaluation's miss, by x
  const auto f = [&](double x) {
    const double m = miss(x);
    misses[x] = m;
    if (tolerance_given && std::abs(m) <= deflection_tolerance_mm) throw CloseEnough{x, m};
    return m;
  };
  try {
    const double f_lo = f(lo), f_hi = f(hi);
    if ((f_lo < 0) == (f_hi < 0)) {
      out.stop_reason = fmt::format("the deflection does not reach the target between the bounds (it misses by {:+.4f} mm at {} = {:g} and "
                                    "{:+.4f} mm at {:g})",
                                    f_lo, variable, lo, f_hi, hi);
      return out;
    }
    boost::uintmax_t iterations = static_cast<boost::uintmax_t>(std::max(1, max_evaluations - 2));
    const auto bracket =
        boost::math::tools::toms748_solve(f, lo, hi, f_lo, f_hi, [&](double a, double b) { return std::abs(b - a) <= 2 * x_tolerance; }, iterations);
    out.from = bracket.first;
    out.to = bracket.second;
    const bool narrow = std::abs(bracket.second - bracket.first) <= 2 * x_tolerance;
    const auto miss_at = [&](double x) {
      const auto it = misses.find(x);
      return it == misses.end() ? std::nan("") : it->second;
    };
    const std::string ends = fmt::format("{} = {:.5g} misses by {:+.4f} mm, {:.5g} by {:+.4f} mm", variable, bracket.first, miss_at(bracket.first),
                                         bracket.second, miss_at(bracket.second));
    if (!narrow) {
      out.stop_reason = fmt::format("max_evaluations reached with the target between {:.5g} and {:.5g} ({})", bracket.first, bracket.second, ends);
    } else if (tolerance_given) {
      // Narrow, and neither end within the deflection's tolerance (that would have stopped the search): a jump.
      out.jump = true;
      out.stop_reason = fmt::format("the deflection jumps across the target within {}'s tolerance: {}; no design between the bounds meets it "
                                    "within {:g} mm",
                                    variable, ends, deflection_tolerance_mm);
    } else {
      out.converged = true;
      out.stop_reason = fmt::format("the target lies between {} = {:.5g} and {:.5g} ({})", variable, bracket.first, bracket.second, ends);
    }
  } catch (const CloseEnough& c) {
    out.converged = true;
    out.stop_reason = fmt::format("the deflection is within its tolerance of the target at {} = {:.5g} (misses by {:+.4f} mm)", variable, c.x, c.miss);
  }
  return out;
}

}  // namespace needle
