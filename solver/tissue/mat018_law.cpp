#include "solver/tissue/mat018_law.h"

#include <cmath>
#include <limits>

namespace needle {

double TissueMaterial::yield_strain() const { return std::pow(E_MPa / k_MPa, 1.0 / (n - 1.0)); }

namespace {

// The rate law in logarithms: factor = 1 + exp(log_term), capped where log_term reaches log_cap. The one place
// rate_factor and rate_factor_uncapped_up_to take them from (rate > 0, the law on).
struct RateLogs {
  double log_term, log_cap;
};

// What the law computes from the card alone, once per card and thread instead of at every point: the yield
// stress at no plastic strain and factor 1 (less 1e-9 of it), and log_cap. The same values as computed at each
// call, so the same results to the last bit.
struct CardConstants {
  double E = 0, k = 0, n = 0, max_rate_factor = 0;
  double initial_yield_floor_MPa = 0, log_cap = 0;
};

const CardConstants& card_constants(const TissueMaterial& m) {
  thread_local CardConstants c;
  if (c.E != m.E_MPa || c.k != m.k_MPa || c.n != m.n || c.max_rate_factor != m.max_rate_factor || c.k == 0) {
    c.E = m.E_MPa, c.k = m.k_MPa, c.n = m.n, c.max_rate_factor = m.max_rate_factor;
    // yield_stress_MPa(eps_p, 1) = k (eps_yp + eps_p)^n is at least k eps_yp^n: pow rises with its base and is
    // accurate to an ulp, far inside the 1e-9 kept in hand.
    c.initial_yield_floor_MPa = m.yield_stress_MPa(0.0, 1.0) * (1 - 1e-9);
    c.log_cap = std::log(m.max_rate_factor - 1.0 > 0 ? m.max_rate_factor - 1.0 : 1e-300);
  }
  return c;
}

RateLogs rate_logs(const TissueMaterial& m, double strain_rate_per_ms) {
  const double exponent = m.rate_law == RateLaw::printed ? 1.0 / m.rate_p : m.rate_p;
  return {exponent * std::log(strain_rate_per_ms / m.rate_C_per_ms), card_constants(m).log_cap};
}

}  // namespace

double TissueMaterial::rate_factor(double strain_rate_per_ms, bool* capped) const {
  if (capped) *capped = false;
  if (rate_law == RateLaw::off || !(strain_rate_per_ms > 0)) return 1.0;
  const auto [log_term, log_cap] = rate_logs(*this, strain_rate_per_ms);
  if (log_term >= log_cap) {
    if (capped) *capped = true;
    return max_rate_factor;
  }
  return 1.0 + std::exp(log_term);
}

double TissueMaterial::yield_stress_MPa(double plastic_strain, double factor) const {
  return factor * k_MPa * std::pow(yield_strain() + plastic_strain, n);
}

double TissueMaterial::hardening_slope_MPa(double plastic_strain, double factor) const {
  return factor * k_MPa * n * std::pow(yield_strain() + plastic_strain, n - 1.0);
}

bool TissueMaterial::rate_factor_uncapped_up_to(double strain_rate_per_ms) const {
  if (rate_law == RateLaw::off || !(strain_rate_per_ms > 0)) return true;
  if (!std::isfinite(strain_rate_per_ms)) return false;
  const RateLogs logs = rate_logs(*this, strain_rate_per_ms);  // log_term rises with the rate
  return logs.log_term < logs.log_cap - 1e-9 * (1 + std::abs(logs.log_cap));
}

double uncapped_rate_limit_per_ms(const TissueMaterial& m) {
  if (m.rate_law == RateLaw::off) return std::numeric_limits<double>::infinity();
  // rate_factor_uncapped_up_to holds while exponent ln(rate / C) < log_cap - 1e-9 (1 + |log_cap|); 1e-6 of the
  // rate below that limit is far beyond the rounding of the logarithm it compares.
  const double exponent = m.rate_law == RateLaw::printed ? 1.0 / m.rate_p : m.rate_p;
  const double log_cap = card_constants(m).log_cap;
  const double log_rate = std::log(m.rate_C_per_ms) + (log_cap - 1e-9 * (1 + std::abs(log_cap))) / exponent;
  return log_rate > 700 ? std::numeric_limits<double>::infinity() : std::exp(log_rate) * (1 - 1e-6);
}

bool rate_stays_uncapped(const TissueMaterial& m, const IncrementStrainRate& rate) {
  // The norm below which the answer is yes, per rate law, cap and step (once per thread while they stay).
  thread_local struct {
    RateLaw law = RateLaw::off;
    double C = -1, p = -1, max_factor = -1, dt = -1, norm = 0;
  } safe;
  if (safe.law != m.rate_law || safe.C != m.rate_C_per_ms || safe.p != m.rate_p || safe.max_factor != m.max_rate_factor ||
      safe.dt != rate.dt_ms()) {
    safe.law = m.rate_law, safe.C = m.rate_C_per_ms, safe.p = m.rate_p, safe.max_factor = m.max_rate_factor, safe.dt = rate.dt_ms();
    safe.norm = IncrementStrainRate::increment_norm_bounded_below(uncapped_rate_limit_per_ms(m), rate.dt_ms());
  }
  if (rate.increment_norm() < safe.norm) return true;
  return m.rate_factor_uncapped_up_to(rate.upper_bound());
}

bool mat018_trial_stays_elastic(const TissueMaterial& m, const IncrementStrainRate& rate, double q_trial, double eps_p) {
  // The rate factor is at least 1 and only raises the yield stress: a trial within the yield stress at factor 1 is
  // elastic at any rate, and where the rate cannot reach the factor's cap either, the rate is not needed (most
  // particles, most steps: it is an eigenvalue problem).
  return (q_trial <= card_constants(m).initial_yield_floor_MPa || q_trial <= m.yield_stress_MPa(eps_p, 1.0)) &&
         rate_stays_uncapped(m, rate);
}

Eigen::Vector3d mat018_deviatoric_stress(const TissueMaterial& m, const IncrementStrainRate& rate, const Eigen::Vector3d& h_dev,
                                         Eigen::Vector3d& h, double& eps_p, bool& capped) {
  const double mu = m.shear_modulus_MPa();
  Eigen::Vector3d s = 2 * mu * h_dev;  // principal deviatoric Cauchy stress
  const double q_trial = std::sqrt(1.5 * s.squaredNorm());
  if (mat018_trial_stays_elastic(m, rate, q_trial, eps_p)) {
    capped = false;
    return s;
  }
  const double factor = m.rate_factor(rate.value(), &capped);
  if (q_trial > m.yield_stress_MPa(eps_p, factor)) {
    // Radial return: q_trial - 3 mu dg = sigma_y(eps_p + dg); Newton with bisection bounds.
    double lo = 0.0, hi = q_trial / (3 * mu), dg = 0.0;
    for (int it = 0; it < 60; ++it) {
      const double residual = q_trial - 3 * mu * dg - m.yield_stress_MPa(eps_p + dg, factor);
      if (residual > 0) lo = dg; else hi = dg;
      if (std::abs(residual) < 1e-12 * q_trial) break;
      double next = dg + residual / (3 * mu + m.hardening_slope_MPa(eps_p + dg, factor));
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      dg = next;
    }
    const Eigen::Vector3d flow = 1.5 * s / q_trial;  // unit plastic flow direction (deviatoric)
    h -= dg * flow;
    s *= 1.0 - 3 * mu * dg / q_trial;
    eps_p += dg;
  }
  return s;
}

double mat018_uniaxial_true_stress_MPa(const TissueMaterial& m, double true_strain, double strain_rate_per_ms) {
  const double factor = m.rate_factor(strain_rate_per_ms);
  const double eps = std::abs(true_strain);
  const double elastic = m.E_MPa * eps;
  if (elastic <= m.yield_stress_MPa(0.0, factor)) return true_strain < 0 ? -elastic : elastic;
  // Plastic: find eps_p in [0, eps] with  E (eps - eps_p) = sigma_y(eps_p); the left side falls and the
  // right side rises with eps_p, so the root is unique.
  double lo = 0.0, hi = eps;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (m.E_MPa * (eps - mid) > m.yield_stress_MPa(mid, factor)) lo = mid; else hi = mid;
  }
  const double stress = m.yield_stress_MPa(0.5 * (lo + hi), factor);
  return true_strain < 0 ? -stress : stress;
}

}  // namespace needle
