#include "solver/tissue/maxwell_relaxation.h"

#include <cmath>

namespace needle {
namespace {

// The rotation of f = R U by the Newton iteration R <- (R + R^-T) / 2 (quadratic; f is near a rotation
// in one increment). Falls back to the last iterate if f is singular enough to stop it.
Eigen::Matrix3d polar_rotation(const Eigen::Matrix3d& f) {
  Eigen::Matrix3d R = f;
  for (int it = 0; it < 30; ++it) {
    const double det = R.determinant();
    if (!(std::abs(det) > 1e-12)) break;
    const Eigen::Matrix3d next = 0.5 * (R + R.inverse().transpose());
    const double change = (next - R).cwiseAbs().maxCoeff();
    R = next;
    if (change < 1e-14) break;
  }
  return R;
}

}  // namespace

void maxwell_relax(const TissueMaterial& m, const Eigen::Matrix3d& f, double dt_ms, const Eigen::Matrix3d& elastic_deviator,
           const MaterialPoint& before, MaterialPoint& after) {
  const Eigen::Matrix3d R = polar_rotation(f);
  const Eigen::Matrix3d q_n = R * before.relaxed_stress_MPa * R.transpose();
  const Eigen::Matrix3d s_n = R * before.elastic_deviator_MPa * R.transpose();
  const double g = m.relaxing_shear_fraction, tau = m.relaxation_time_ms;
  if (dt_ms > 0) {
    const double ratio = dt_ms / tau, a = std::exp(-ratio);
    // 1 - (1 - a) / ratio, by its series where the division would lose digits.
    const double lag = ratio < 1e-4 ? ratio / 2 - ratio * ratio / 6 : 1 - (1 - a) / ratio;
    // q_n+1 = a q_n + g [(1 - a) s_n + lag (s_n+1 - s_n)]
    after.relaxed_stress_MPa = a * q_n + g * ((1 - a) * s_n + lag * (elastic_deviator - s_n));
  } else {
    after.relaxed_stress_MPa = q_n;
  }
  after.elastic_deviator_MPa = elastic_deviator;
}

}  // namespace needle
