// The tissue's stable time step (spg_tissue.h): the shortest support's current length over the wave speed,
// for the whole tissue and for each particle (the mass scaling's), and the smallest principal stretch of F it
// needs, bounded cheaply at every force evaluation and computed from F's eigenvalues only where a step needs it.
#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

#include "core/parallel.h"
#include "solver/tissue/spg_tissue.h"

namespace needle {
namespace {

// Smallest principal stretch of F (the square root of the smallest eigenvalue of F^T F).
double smallest_stretch(const Mat3d& F) {
  Eigen::SelfAdjointEigenSolver<Mat3d> eig;
  eig.computeDirect(F.transpose() * F, Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(eig.eigenvalues()[0], 0.0));
}

// Bounds on smallest_stretch(F) without the eigenvalues (which cost a cubic's trigonometry per particle and
// step, though only the few most squeezed particles set the step). Below: the square root of the larger of
// Gershgorin's bound on C = F^T F and 4 det C / tr(C)^2 (as lambda_2 lambda_3 <= (tr C / 2)^2); above: F's
// shortest column (|F v| for a unit v). Each widened by 1e-9, far beyond the eigensolver's rounding.
constexpr double kStretchBoundSlack = 1e-9;
void stretch_bounds(const Mat3d& F, double& lower, double& upper) {
  const Mat3d C = F.transpose() * F;
  double gershgorin = std::numeric_limits<double>::infinity();
  for (int r = 0; r < 3; ++r) gershgorin = std::min(gershgorin, C(r, r) - std::abs(C(r, (r + 1) % 3)) - std::abs(C(r, (r + 2) % 3)));
  const double trace = C.trace();
  const double lower_squared = std::max({gershgorin, trace > 0 ? 4 * C.determinant() / (trace * trace) : 0.0, 0.0});
  lower = std::sqrt(lower_squared) * (1 - kStretchBoundSlack);
  upper = std::sqrt(std::min({C(0, 0), C(1, 1), C(2, 2)})) * (1 + kStretchBoundSlack);
}

}  // namespace

void SpgTissue::set_stretch_bounds(size_t s) {
  stretch_bounds(p_.deformation_gradient[s], stretch_lower_[s], stretch_upper_[s]);
  min_stretch_[s] = -1;  // not computed yet: min_stretch(s) does when a step needs it
}

double SpgTissue::min_stretch(size_t s) const {
  if (min_stretch_[s] < 0) min_stretch_[s] = smallest_stretch(p_.deformation_gradient[s]);
  return min_stretch_[s];
}

double SpgTissue::stable_time_step_ms() const {
  const double factor = options_.stabilization == Stabilization::penalty ? 1.0 + 4.0 * options_.stabilization_coefficient : 1.0;
  // The shortest support's current length and the stiffest point of a stiffening law, per chunk in parallel and
  // then over the chunks (min and max are exact in any order). The shortest is looked for among the particles
  // whose stretch's lower bound could reach the smallest upper bound: the same minimum as over all.
  std::mutex merge;
  double bound = std::numeric_limits<double>::infinity();  // some support is at most this short
  double largest_strain = 0;  // the stiffest point of a stiffening law
  parallel_for(p_.size(), [&](std::int64_t begin, std::int64_t end) {
    double chunk_bound = std::numeric_limits<double>::infinity(), chunk_strain = 0;
    for (std::int64_t i = begin; i < end; ++i) {
      const size_t s = static_cast<size_t>(i);
      if (!rk_.valid[s]) continue;
      chunk_bound = std::min(chunk_bound, stable_length_mm_[s] * stretch_upper_[s]);
      chunk_strain = std::max(chunk_strain, p_.effective_strain[s] - p_.plastic_strain[s]);
    }
    const std::lock_guard<std::mutex> lock(merge);
    bound = std::min(bound, chunk_bound);
    largest_strain = std::max(largest_strain, chunk_strain);
  });
  double shortest = std::numeric_limits<double>::infinity();  // current length of the shortest support
  parallel_for(p_.size(), [&](std::int64_t begin, std::int64_t end) {
    double chunk_shortest = std::numeric_limits<double>::infinity();
    for (std::int64_t i = begin; i < end; ++i) {
      const size_t s = static_cast<size_t>(i);
      if (rk_.valid[s] && stable_length_mm_[s] * stretch_lower_[s] <= bound)
        chunk_shortest = std::min(chunk_shortest, stable_length_mm_[s] * min_stretch(s));
    }
    const std::lock_guard<std::mutex> lock(merge);
    shortest = std::min(shortest, chunk_shortest);
  });
  const double wave_speed = std::sqrt(material_.tangent_p_wave_modulus_MPa(largest_strain) * factor / material_.density_g_per_mm3());
  return options_.cfl * shortest / wave_speed;
}

void SpgTissue::particle_time_steps_ms(std::vector<double>& dt_ms, double known_above_ms) const {
  const double factor = options_.stabilization == Stabilization::penalty ? 1.0 + 4.0 * options_.stabilization_coefficient : 1.0;
  const double rho = material_.density_g_per_mm3();
  dt_ms.resize(static_cast<size_t>(p_.size()));
  parallel_for(p_.size(), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) {
      const size_t s = static_cast<size_t>(i);
      if (!rk_.valid[s]) {
        dt_ms[s] = std::numeric_limits<double>::infinity();
        continue;
      }
      const double strain = p_.effective_strain[s] - p_.plastic_strain[s];
      const double wave_speed = std::sqrt(material_.tangent_p_wave_modulus_MPa(std::max(strain, 0.0)) * factor / rho);
      const double at_least = options_.cfl * stable_length_mm_[s] * stretch_lower_[s] / wave_speed;
      dt_ms[s] = at_least >= known_above_ms ? at_least : options_.cfl * stable_length_mm_[s] * min_stretch(s) / wave_speed;
    }
  });
}

}  // namespace needle
