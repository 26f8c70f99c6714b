#include "solver/tissue/tissue_material.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <string>
#include <vector>

#include "core/input_error.h"
#include "solver/tissue/hencky_strain.h"
#include "solver/tissue/maxwell_relaxation.h"
#include "solver/tissue/mat018_law.h"
#include "solver/tissue/stiffening_elastic_law.h"

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

std::string TissueMaterial::describe() const {
  std::vector<std::string> parts;
  if (law == TissueLaw::stiffening_elastic) parts.emplace_back("the tissue stiffens as measured (stiffening_elastic: 3 G eps + k eps^n)");
  if (viscoelastic())
    parts.push_back(fmt::format("the gel relaxes viscoelastically ({:g} of the shear stress, time constant {:g} ms)", relaxing_shear_fraction,
                                relaxation_time_ms));
  return fmt::format("{}", fmt::join(parts, "; "));
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

double TissueMaterial::tangent_shear_modulus_MPa(double effective_strain) const {
  if (law == TissueLaw::mat018) return shear_modulus_MPa();
  return shear_modulus_MPa() + k_MPa * n * std::pow(std::max(effective_strain, 0.0), n - 1.0) / 3.0;
}

double TissueMaterial::tangent_p_wave_modulus_MPa(double effective_strain) const {
  if (law == TissueLaw::mat018) return p_wave_modulus_MPa();  // the same value, kept to the last bit for stored runs
  return bulk_modulus_MPa() + 4.0 / 3.0 * tangent_shear_modulus_MPa(effective_strain);
}

double IncrementStrainRate::value() const {
  if (value_ >= 0) return value_;
  value_ = 0.0;
  if (dt_ms_ > 0) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> inc;
    inc.computeDirect(f_ * f_.transpose(), Eigen::EigenvaluesOnly);
    Eigen::Vector3d d = 0.5 * inc.eigenvalues().cwiseMax(1e-300).array().log().matrix();
    d.array() -= d.mean();
    value_ = std::sqrt(2.0 / 3.0 * d.squaredNorm()) / dt_ms_;
  }
  return value_;
}

namespace {
constexpr double kBoundSlack = 1e-6, kBoundFloor = 1e-12;  // upper_bound's margins over value()'s rounding
}

double IncrementStrainRate::upper_bound() const {
  if (!(dt_ms_ > 0)) return 0.0;
  const double r = increment_norm();  // bounds |eig(f f^T) - 1|
  if (!(r < 0.5)) return std::numeric_limits<double>::infinity();
  // |dev d| <= |d| <= sqrt(3) max |d_i|, so the rate <= sqrt(2/3) sqrt(3) (-1/2 ln(1 - r)) / dt; the margins cover the
  // rounding of the eigenvalues and logarithms value() computes (about 1e-16 each).
  return (std::sqrt(0.5) * -std::log1p(-r) * (1 + kBoundSlack) + kBoundFloor) / dt_ms_;
}

double IncrementStrainRate::increment_norm_bounded_below(double rate_per_ms, double dt_ms) {
  if (!(dt_ms > 0)) return std::numeric_limits<double>::infinity();  // upper_bound() is 0
  if (!(rate_per_ms > 0)) return 0.0;
  // upper_bound() solved for r: -ln(1 - r) = (rate dt - floor) / (sqrt(1/2) (1 + slack)).
  const double y = (rate_per_ms * dt_ms - kBoundFloor) / (std::sqrt(0.5) * (1 + kBoundSlack));
  if (!(y > 0)) return 0.0;
  const double r = std::isfinite(y) ? -std::expm1(-y) : 1.0;
  return std::min(r, 0.5) * (1 - 1e-6);
}

namespace {

// The update of a trial that stays elastic, from its Hencky strain H = 1/2 ln(b_trial) as a matrix: each law's
// deviatoric stress is then a multiple of dev H (2 mu, or the stiffening law's secant 2 mu_s), and b_e is the
// trial itself (exp(2 H) = b_trial). False where MAT_018 would flow or its rate could reach the cap.
bool update_elastic_trial(const TissueMaterial& m, const MaterialPoint& state, const Eigen::Matrix3d& f, double dt_ms,
                          const Eigen::Matrix3d& b_trial, const Eigen::Matrix3d& H, const IncrementStrainRate& rate, StressUpdate& out) {
  const double mu = m.shear_modulus_MPa(), lambda = m.lame_lambda_MPa();
  const double volumetric = H.trace();
  Eigen::Matrix3d H_dev = H;
  H_dev.diagonal().array() -= volumetric / 3.0;
  const double eps_eq = std::sqrt(2.0 / 3.0 * H_dev.squaredNorm());
  double shear_factor = 0;  // the deviatoric stress per unit dev H
  switch (m.law) {
    case TissueLaw::mat018:
      if (!mat018_trial_stays_elastic(m, rate, std::sqrt(1.5) * 2 * mu * H_dev.norm(), state.plastic_strain)) return false;
      shear_factor = 2 * mu;
      break;
    case TissueLaw::stiffening_elastic: shear_factor = 2 * stiffening_elastic_secant_shear_modulus_MPa(m, eps_eq); break;
  }
  const Eigen::Matrix3d s = shear_factor * H_dev;
  out.state.elastic_left_cauchy_green = 0.5 * (b_trial + b_trial.transpose());
  out.state.plastic_strain = state.plastic_strain;
  out.cauchy_stress_MPa = s;
  out.cauchy_stress_MPa.diagonal().array() += (lambda + 2.0 * mu / 3.0) * volumetric;
  if (m.viscoelastic()) {
    maxwell_relax(m, f, dt_ms, s, state, out.state);
    out.cauchy_stress_MPa -= out.state.relaxed_stress_MPa;
  }
  out.rate_factor_capped = false;
  out.effective_strain = state.plastic_strain + eps_eq;
  return true;
}

// The update in the principal axes of the elastic trial b_trial = f b_e f^T, with the increment's effective strain
// rate (from the deviatoric log strain of f f^T: the law asks for it).
StressUpdate update_in_principal_axes(const TissueMaterial& m, const MaterialPoint& state, const Eigen::Matrix3d& f, double dt_ms,
                                      const Eigen::Matrix3d& b_trial, const IncrementStrainRate& rate) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(b_trial);
  const Eigen::Vector3d lambda_sq = eig.eigenvalues().cwiseMax(1e-300);
  Eigen::Vector3d h = 0.5 * lambda_sq.array().log().matrix();
  bool capped = false;

  const double mu = m.shear_modulus_MPa(), lambda = m.lame_lambda_MPa();
  const double volumetric = h.sum();
  const Eigen::Vector3d h_dev = h.array() - volumetric / 3.0;
  const double eps_eq = std::sqrt(2.0 / 3.0 * h_dev.squaredNorm());
  // The law's deviatoric principal Cauchy stress (each law in its own file); MAT_018 may flow plastically,
  // which moves h and eps_p.
  double eps_p = state.plastic_strain;
  Eigen::Vector3d s;
  switch (m.law) {
    case TissueLaw::mat018: s = mat018_deviatoric_stress(m, rate, h_dev, h, eps_p, capped); break;
    case TissueLaw::stiffening_elastic: s = stiffening_elastic_deviatoric_stress(m, h_dev, eps_eq); break;
  }
  const Eigen::Matrix3d& V = eig.eigenvectors();
  const Eigen::Vector3d sigma_principal = s.array() + (lambda + 2.0 * mu / 3.0) * volumetric;
  StressUpdate out;
  out.state.elastic_left_cauchy_green = V * (2.0 * h).array().exp().matrix().asDiagonal() * V.transpose();
  out.state.plastic_strain = eps_p;
  out.cauchy_stress_MPa = V * sigma_principal.asDiagonal() * V.transpose();
  if (m.viscoelastic()) {
    maxwell_relax(m, f, dt_ms, V * s.asDiagonal() * V.transpose(), state, out.state);
    out.cauchy_stress_MPa -= out.state.relaxed_stress_MPa;
  }
  out.rate_factor_capped = capped;
  const Eigen::Vector3d h_dev_final = h.array() - h.mean();
  out.effective_strain = eps_p + std::sqrt(2.0 / 3.0 * h_dev_final.squaredNorm());
  return out;
}

}  // namespace

StressUpdate update_stress(const TissueMaterial& m, const MaterialPoint& state, const Eigen::Matrix3d& f, double dt_ms) {
  const Eigen::Matrix3d b_trial = f * state.elastic_left_cauchy_green * f.transpose();
  const IncrementStrainRate rate(f, dt_ms);
  Eigen::Matrix3d H;
  StressUpdate out;
  if (hencky_strain_near_identity(b_trial, H) && update_elastic_trial(m, state, f, dt_ms, b_trial, H, rate, out)) return out;
  return update_in_principal_axes(m, state, f, dt_ms, b_trial, rate);
}

StressUpdate update_stress_by_eigenvalues(const TissueMaterial& m, const MaterialPoint& state, const Eigen::Matrix3d& f, double dt_ms) {
  return update_in_principal_axes(m, state, f, dt_ms, f * state.elastic_left_cauchy_green * f.transpose(), IncrementStrainRate(f, dt_ms));
}

double uniaxial_true_stress_MPa(const TissueMaterial& m, double true_strain, double strain_rate_per_ms) {
  switch (m.law) {
    case TissueLaw::stiffening_elastic: return stiffening_elastic_uniaxial_true_stress_MPa(m, true_strain);
    case TissueLaw::mat018: break;
  }
  return mat018_uniaxial_true_stress_MPa(m, true_strain, strain_rate_per_ms);
}

void keep_pressure_only(StressUpdate& update) {
  Eigen::Matrix3d& sigma = update.cauchy_stress_MPa;
  sigma = (sigma.trace() / 3.0) * Eigen::Matrix3d::Identity();
  Eigen::Matrix3d& b = update.state.elastic_left_cauchy_green;
  b = std::cbrt(std::max(b.determinant(), 0.0)) * Eigen::Matrix3d::Identity();
  update.state.relaxed_stress_MPa.setZero();
  update.state.elastic_deviator_MPa.setZero();
}

}  // namespace needle
