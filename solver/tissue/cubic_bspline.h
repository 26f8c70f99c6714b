#pragma once
// The cubic B-spline kernel of the SPG tissue, on a support of radius a: with z = r / a,
//   phi(z) = 2/3 - 4 z^2 + 4 z^3            for 0 <= z <= 1/2
//          = 4/3 - 4 z + 4 z^2 - 4/3 z^3    for 1/2 < z <= 1
//          = 0                              beyond.
// C2-continuous; the RK correction makes the shape functions exact for linear fields, so the kernel's
// own normalisation does not matter.
namespace needle {

double cubic_bspline(double z);
// d phi / d z
double cubic_bspline_derivative(double z);

}  // namespace needle
