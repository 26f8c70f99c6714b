#pragma once
// Euler-Bernoulli references for the needle's FE model: the tip compliance of a cantilever whose
// bending stiffness E I(x) varies along x (the real, grooved and bevelled sections).
#include <functional>
#include <vector>

namespace needle {

// Displacement at x = point_x_mm per newton at x = load_x_mm of a beam clamped at clamp_x_mm
// (unit-load method): integral over [clamp, min(load, point)] of (load - x)(point - x) / (E I(x)).
// `breakpoints` are where I(x) has kinks or jumps (groove ends, heel); the integral is composite
// Simpson on each piece with steps no longer than step_mm.
double cantilever_compliance_mm_per_N(const std::function<double(double x_mm)>& second_moment_mm4, double youngs_modulus_MPa,
                                      double clamp_x_mm, double load_x_mm, double point_x_mm,
                                      std::vector<double> breakpoints, double step_mm = 0.05);

}  // namespace needle
