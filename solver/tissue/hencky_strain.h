#pragma once
// The Hencky strain H = 1/2 log b of a symmetric positive definite b (a left Cauchy-Green tensor) near the
// identity, without its eigenvectors: the series 1/2 log b = artanh Y = sum Y^(2k+1) / (2k+1) with
// Y = (b - I)(b + I)^-1, which shares b's eigenvectors and has the eigenvalues (l - 1) / (l + 1). The stress update
// of a particle that stays elastic needs H only through isotropic functions (its deviator, trace and norm), so it
// skips the 3x3 eigenvalue problem, which costs a cubic's trigonometry per particle and step.
#include <Eigen/Dense>

namespace needle {

// |Y|_F up to which hencky_strain_near_identity sums its series (the principal stretches squared then lie within
// [0.6, 1.67]); beyond it the caller takes the eigenvalues.
constexpr double kHenckySeriesLimit = 0.25;

// H = 1/2 log b, summed until the remainder's bound lies below 1e-17 of |H| (at most 13 terms, at the limit); false,
// with H untouched, where |Y|_F exceeds kHenckySeriesLimit or b is not finite. b is read as symmetric (its lower
// triangle).
bool hencky_strain_near_identity(const Eigen::Matrix3d& b, Eigen::Matrix3d& H);

}  // namespace needle
