#pragma once
// Where one design variable makes the deflection its target (`needle optimize`'s toms748 method): the sign change of
// miss(x) = delta(x) - target between the bounds, kept and shrunk by Boost.Math's TOMS 748 (interpolation steps,
// bisection where they stall) until the bracket is narrower than twice the variable's tolerance, or until a design
// meets the target within the deflection's tolerance.
//
// "Converged" means what a user reads it to mean: a design was found whose deflection meets the target within its
// tolerance (or, with no deflection tolerance given, the bracket is as narrow as the variable's). A narrow bracket
// whose two ends both miss by more than the deflection's tolerance is not that: delta jumps across the target there
// (a separation that snaps, a contact that switches), and the search says so, with both ends' deflections.
#include <functional>
#include <string>

namespace needle {

struct TargetBracket {
  bool converged = false;
  bool jump = false;         // the bracket narrowed to the variable's tolerance across a jump of delta
  double from = 0, to = 0;   // the last bracket (both NaN when there was none: no sign change, a stop, a design within tolerance)
  std::string stop_reason;   // in words, with the numbers
};

// miss(x): delta(x) - target in mm, for x within [lo, hi]; it may throw to stop the search (the exception passes
// through). deflection_tolerance_mm NaN: none. max_evaluations counts the two at the bounds.
TargetBracket bracket_target(const std::function<double(double)>& miss, const std::string& variable, double lo, double hi, double x_tolerance,
                             double deflection_tolerance_mm, int max_evaluations);

}  // namespace needle
