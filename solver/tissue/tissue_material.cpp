#include "solver/tissue/tissue_material.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "core/input_error.h"

namespace needle {

RateLaw rate_law_from_name(const std::string& name) {
  if (name == "off") return RateLaw::off;
  if (name == "on" || name == "plausible") return RateLaw::plausible;
  if (name == "printed") return RateLaw::printed;
  throw InputError(fmt::format("rate law '{}' is not one of off, on (= plausible), printed", name));
}

TissueLaw tissue_law_from_name(const std::string& name) {
  if (name == "mat018") return TissueLaw::mat018;
  if (name == "stiffening_elastic") return TissueLaw::stiffening_elastic;
  throw InputError(fmt::format("tissue law '{}' is not one of mat018, stiffening_elastic", name));
}

std::string tissue_law_name(TissueLaw law) { return law == TissueLaw::stiffening_elastic ? "stiffening_elastic" : "mat018"; }

std::string rate_law_name(RateLaw law) {
  switch (law) {
    case RateLaw::off: return "off";
    case RateLaw::plausible: return "plausible";
    case RateLaw::printed: return "printed";
  }
  return "off";
}

void TissueMaterial::validate() const {
  auto finite_positive = [](double v) { return std::isfinite(v) && v > 0; };
  NEEDLE_REQUIRE(finite_positive(E_MPa), fmt::format("tissue E_MPa must be a positive modulus (got {})", E_MPa));
  NEEDLE_REQUIRE(std::isfinite(nu) && nu > -1.0 && nu < 0.5,
                 fmt::format("tissue nu must lie in (-1, 0.5) (got {}); 0.5 would be incompressible", nu));
  NEEDLE_REQUIRE(finite_positive(density_g_per_cm3), fmt::format("tissue density_g_per_cm3 must be positive (got {})", density_g_per_cm3));
  NEEDLE_REQUIRE(finite_positive(k_MPa), fmt::format("tissue k_MPa must be positive (got {})", k_MPa));
  NEEDLE_REQUIRE(std::isfinite(n) && n > 1.0 && n < 20.0,
                 fmt::format("tissue hardening exponent n must lie in (1, 20) (got {}); eps_yp = (E/k)^(1/(n-1))", n));
  NEEDLE_REQUIRE(finite_positive(rate_C_per_ms), fmt::format("rate law C_per_ms must be positive (got {})", rate_C_per_ms));
  NEEDLE_REQUIRE(finite_positive(rate_p), fmt::format("rate law p must be positive (got {})", rate_p));
  NEEDLE_REQUIRE(std::isfinite(max_rate_factor) && max_rate_factor >= 1.0,
                 fmt::format("max_rate_factor must be >= 1 (got {})", max_rate_factor));
  NEEDLE_REQUIRE(std::isfinite(relaxing_shear_fraction) && relaxing_shear_fraction >= 0 && relaxing_shear_fraction < 1,
                 fmt::format("tissue relaxing_shear_fraction must lie in [0, 1) (got {}); 1 would leave no relaxed modulus",
                             relaxing_shear_fraction));
  NEEDLE_REQUIRE(finite_positive(relaxation_time_ms), fmt::format("tissue relaxation_time_ms must be positive (got {})", relaxation_time_ms));
  if (law == TissueLaw::stiffening_elastic) return;  // no yield strain to check
  const double eps_yp = yield_strain();
  NEEDLE_REQUIRE(std::isfinite(eps_yp) && eps_yp < 100.0,
                 fmt::format("E = {} MPa with k = {} MPa, n = {} gives a yield strain {:.3g}: the card never yields", E_MPa, k_MPa, n, eps_yp));
}

double TissueMaterial::yield_strain() const { return std::pow(E_MPa / k_MPa, 1.0 / (n - 1.0)); }

double TissueMaterial::equivalent_stress_MPa(double eps) const {
  return 3 * shear_modulus_MPa() * eps + k_MPa * std::pow(std::max(eps, 0.0), n);
}

double TissueMaterial::tangent_shear_modulus_MPa(double effective_strain) const {
  if (law == TissueLaw::mat018) return shear_modulus_MPa();
  return shear_modulus_MPa() + k_MPa * n * std::pow(std::max(effective_strain, 0.0), n - 1.0) / 3.0;
}

double TissueMaterial::tangent_p_wave_modulus_MPa(double effective_strain) const {
  if (law == TissueLaw::mat018) return p_wave_modulus_MPa();  // the same value, kept to the last bit for stored runs
  return bulk_modulus_MPa() + 4.0 / 3.0 * tangent_shear_modulus_MPa(effective_strain);
}

double TissueMaterial::rate_factor(double strain_rate_per_ms, bool* capped) const {
  if (capped) *capped = false;
  if (rate_law == RateLaw::off || !(strain_rate_per_ms > 0)) return 1.0;
  const double exponent = rate_law == RateLaw::printed ? 1.0 / rate_p : rate_p;
  const double log_term = exponent * std::log(strain_rate_per_ms / rate_C_per_ms);
  const double log_cap = std::log(max_rate_factor - 1.0 > 0 ? max_rate_factor - 1.0 : 1e-300);
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

// The Maxwell branch over one increment (see MaterialPoint): exact for s_e linear in time.
void relax(const TissueMaterial& m, const Eigen::Matrix3d& f, double dt_ms, const Eigen::Matrix3d& elastic_deviator,
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

}  // namespace

StressUpdate update_stress(const TissueMaterial& m, const MaterialPoint& state, const Eigen::Matrix3d& f, double dt_ms) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  // Elastic trial: b_e = f b_e f^T, principal log strains.
  const Eigen::Matrix3d b_trial = f * state.elastic_left_cauchy_green * f.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(b_trial);
  const Eigen::Vector3d lambda_sq = eig.eigenvalues().cwiseMax(1e-300);
  Eigen::Vector3d h = 0.5 * lambda_sq.array().log().matrix();

  // Effective strain rate of the increment, from the deviatoric log strain of f f^T.
  double rate = 0.0;
  if (dt_ms > 0) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> inc;
    inc.computeDirect(f * f.transpose(), Eigen::EigenvaluesOnly);
    Eigen::Vector3d d = 0.5 * inc.eigenvalues().cwiseMax(1e-300).array().log().matrix();
    d.array() -= d.mean();
    rate = std::sqrt(2.0 / 3.0 * d.squaredNorm()) / dt_ms;
  }
  bool capped = false;
  const double factor = m.law == TissueLaw::mat018 ? m.rate_factor(rate, &capped) : 1.0;

  const double mu = m.shear_modulus_MPa(), lambda = m.lame_lambda_MPa();
  const double volumetric = h.sum();
  const Eigen::Vector3d h_dev = h.array() - volumetric / 3.0;
  const double eps_eq = std::sqrt(2.0 / 3.0 * h_dev.squaredNorm());
  // Secant shear modulus: q(eps) / (3 eps); mu itself for the linear card (and at eps = 0).
  const double secant_mu = m.law == TissueLaw::stiffening_elastic && eps_eq > 0 ? m.equivalent_stress_MPa(eps_eq) / (3 * eps_eq) : mu;
  Eigen::Vector3d s = 2 * secant_mu * h_dev;  // principal deviatoric Cauchy stress
  const double q_trial = std::sqrt(1.5 * s.squaredNorm());
  double eps_p = state.plastic_strain;
  if (m.law == TissueLaw::mat018 && q_trial > m.yield_stress_MPa(eps_p, factor)) {
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
  const Eigen::Matrix3d& V = eig.eigenvectors();
  const Eigen::Vector3d sigma_principal = s.array() + (lambda + 2.0 * mu / 3.0) * volumetric;
  StressUpdate out;
  out.state.elastic_left_cauchy_green = V * (2.0 * h).array().exp().matrix().asDiagonal() * V.transpose();
  out.state.plastic_strain = eps_p;
  out.cauchy_stress_MPa = V * sigma_principal.asDiagonal() * V.transpose();
  if (m.viscoelastic()) {
    relax(m, f, dt_ms, V * s.asDiagonal() * V.transpose(), state, out.state);
    out.cauchy_stress_MPa -= out.state.relaxed_stress_MPa;
  }
  out.rate_factor_capped = capped;
  const Eigen::Vector3d h_dev_final = h.array() - h.mean();
  out.effective_strain = eps_p + std::sqrt(2.0 / 3.0 * h_dev_final.squaredNorm());
  (void)I;
  return out;
}

double uniaxial_true_stress_MPa(const TissueMaterial& m, double true_strain, double strain_rate_per_ms) {
  if (m.law == TissueLaw::stiffening_elastic) {
    // Uniaxial stress: h = (e, -t, -t) with sigma = q(2/3 (e + t)) and sigma / 3 = K (e - 2 t); solve the
    // lateral contraction t by bisection (q rises with t, the volumetric pressure falls).
    const double e = std::abs(true_strain), K = m.bulk_modulus_MPa();
    double lo = -e, hi = e;
    for (int it = 0; it < 200; ++it) {
      const double t = 0.5 * (lo + hi);
      if (m.equivalent_stress_MPa(2.0 / 3.0 * (e + t)) > 3 * K * (e - 2 * t)) hi = t; else lo = t;
    }
    const double stress = 3 * K * (e - lo - hi);  // 3 K (e - 2 t) at t = (lo + hi) / 2
    return true_strain < 0 ? -stress : stress;
  }
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
