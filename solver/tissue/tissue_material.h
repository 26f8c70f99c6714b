#pragma once
// The tissue card: isotropic elasticity with power-law isotropic hardening, LS-DYNA MAT_018 semantics:
//   sigma_y = rate_factor * k * (eps_yp + eps_p)^n,    eps_yp = (E / k)^(1 / (n - 1))
// (eps_yp is the strain at which the elastic line E eps meets k eps^n). Stress update: see update_stress.
//
// Rate factor (Cowper-Symonds) 1 + (rate / C)^exponent on the effective strain rate. The paper prints
// C = 0.1 /ms, p = 0.1 with exponent 1/p = 10: ~1e20 at the strain rates near the tip, so the material
// could never yield. The plausible reading swaps p and 1/p (exponent 0.1: factor ~2.6 at 1e4 /s). Both
// are supported; the plausible one is the default. The factor is computed in logs and capped at
// max_rate_factor, so it never overflows; the solver counts the capped evaluations.
//
// Units: MPa, mm, ms, g. Defaults are the paper's PVC card; E is not in the paper (docs/solver.md):
// 0.665 MPa is the E for which this card's uniaxial curve best fits the paper's own fitted curve
// 0.35 eps^2.75 over 0 <= eps <= 1.84 (RMS 0.285 MPa; a MAT_018 card with n > 1 is linear up to
// eps_yp, so no E fits it closely). It is the parameter issue 7 calibrates on the SB needle.
#include <Eigen/Dense>
#include <string>

namespace needle {

enum class RateLaw { off, plausible, printed };

// Which constitutive law the card follows.
// - mat018: the paper's card (LS-DYNA MAT_018), linear to eps_yp, then plastic on k eps^n. With n > 1
//   it is nearly linear at every strain: its curve never follows the measured k eps^n, which stiffens.
// - stiffening_elastic: hyperelastic in the Hencky strain, with the equivalent stress
//   q(eps) = 3 G eps + k eps^n of the equivalent log strain eps (G from E and nu): small-strain modulus E,
//   then the paper's measured power law on top, so the gel stiffens as in its compression test.
//   Volumetric part linear, K from E and nu. No plasticity; the rate law does not apply (it scales a
//   yield stress, and this law has none).
enum class TissueLaw { mat018, stiffening_elastic };

TissueLaw tissue_law_from_name(const std::string& name);  // "mat018", "stiffening_elastic"
std::string tissue_law_name(TissueLaw law);

RateLaw rate_law_from_name(const std::string& name);  // "off", "on"/"plausible", "printed"
std::string rate_law_name(RateLaw law);

struct TissueMaterial {
  TissueLaw law = TissueLaw::mat018;
  double E_MPa = 0.665;
  double nu = 0.45;
  double density_g_per_cm3 = 0.98;
  double k_MPa = 0.35;
  double n = 2.75;
  RateLaw rate_law = RateLaw::plausible;
  double rate_C_per_ms = 0.1;  // Cowper-Symonds C
  double rate_p = 0.1;         // Cowper-Symonds p (exponent 1/p for `printed`, p for `plausible`)
  double max_rate_factor = 1e3;
  // Viscoelastic relaxation of the shear stress (one Maxwell branch, off by default): a step of shear
  // strain held still gives the deviatoric stress s(t) = s_0 (1 - g (1 - exp(-t / tau))), g the
  // relaxing shear fraction and tau the relaxation time. E is the instantaneous modulus (the wave speed
  // and stable step are unchanged); (1 - g) E is the relaxed one. The paper's card has none (g = 0).
  double relaxing_shear_fraction = 0.0;  // g in [0, 1)
  double relaxation_time_ms = 1.0;       // tau > 0
  bool viscoelastic() const { return relaxing_shear_fraction > 0; }

  // InputError naming the bad field: E <= 0, nu outside (-1, 0.5), density <= 0, k <= 0, n <= 1, ...
  void validate() const;  // also g outside [0, 1), tau <= 0
  // The law and the relaxation in a run's one-line description (the paper report), "; " between them; empty for the
  // paper's card's (MAT_018, no relaxation), which goes unnamed.
  std::string describe() const;

  double density_g_per_mm3() const { return density_g_per_cm3 * 1e-3; }
  double shear_modulus_MPa() const { return E_MPa / (2 * (1 + nu)); }
  double lame_lambda_MPa() const { return E_MPa * nu / ((1 + nu) * (1 - 2 * nu)); }
  double p_wave_modulus_MPa() const { return lame_lambda_MPa() + 2 * shear_modulus_MPa(); }  // at zero strain
  double bulk_modulus_MPa() const { return E_MPa / (3 * (1 - 2 * nu)); }
  // The tangent shear modulus at an (elastic) effective strain, dq/deps / 3: G for mat018 (plastic flow
  // only softens), G + k n eps^(n-1) / 3 for stiffening_elastic.
  double tangent_shear_modulus_MPa(double effective_strain) const;
  // K + 4/3 of that: the stable step's wave speed (the elastic P-wave modulus for mat018).
  double tangent_p_wave_modulus_MPa(double effective_strain) const;
  // stiffening_elastic: q(eps) = 3 G eps + k eps^n, the equivalent (von Mises) stress at an equivalent
  // log strain eps >= 0.
  double equivalent_stress_MPa(double equivalent_strain) const;
  double yield_strain() const;  // eps_yp
  // Rate factor at an effective strain rate (1/ms); `capped` set when the cap applied.
  double rate_factor(double strain_rate_per_ms, bool* capped = nullptr) const;
  // Whether rate_factor stays below its cap for every rate up to this one (rate_factor never falls below 1).
  bool rate_factor_uncapped_up_to(double strain_rate_per_ms) const;
  double yield_stress_MPa(double plastic_strain, double rate_factor) const;
  double hardening_slope_MPa(double plastic_strain, double rate_factor) const;
};

// The effective strain rate of an increment f over dt_ms, sqrt(2/3 |dev d|^2) / dt with d = 1/2 ln eig(f f^T)
// (0 when dt is 0). value() solves the eigenvalue problem, once, when first asked; upper_bound() needs only
// |f f^T - I|: every eigenvalue of f f^T lies within that of 1, so |d_i| <= -1/2 ln(1 - |f f^T - I|).
class IncrementStrainRate {
 public:
  IncrementStrainRate(const Eigen::Matrix3d& f, double dt_ms) : f_(f), dt_ms_(dt_ms) {}
  double value() const;
  double upper_bound() const;  // >= value(), rounding included; infinite for increments beyond |f f^T - I| = 1/2
  double increment_norm() const { return (f_ * f_.transpose() - Eigen::Matrix3d::Identity()).norm(); }  // |f f^T - I|
  double dt_ms() const { return dt_ms_; }
  // The largest |f f^T - I| whose upper_bound() stays below rate_per_ms, less 1e-6 of it (far beyond the
  // rounding of upper_bound, which rises with the norm): 0 where none does.
  static double increment_norm_bounded_below(double rate_per_ms, double dt_ms);

 private:
  Eigen::Matrix3d f_;
  double dt_ms_;
  mutable double value_ = -1;  // < 0: not computed yet
};

// Material state at one point and its update over one increment. Elasticity is Hencky's, written in
// Cauchy stress: sigma = lambda tr(h) I + 2 mu h with h = 1/2 ln(b_e) the elastic log strain (b_e the
// elastic left Cauchy-Green tensor). For coaxial paths (uniaxial tension) this is exactly what
// LS-DYNA's hypoelastic MAT_018 integrates, sigma = E eps_e in true stress and log strain; unlike the
// Jaumann-rate form it stays stable when the stress exceeds the shear modulus (elastic strains near 1,
// which this soft card reaches). Plasticity: multiplicative, J2 return mapping in principal log strain
// (exponential map), so plastic flow is exactly volume preserving.
//
// Viscoelastic relaxation (TissueMaterial::viscoelastic): the Maxwell branch's stress q obeys
// dq/dt = (g s_e - q) / tau, s_e the deviatoric stress of the elastic(-plastic) update above, and the
// Cauchy stress is that update's minus q. s_e is taken linear in time over the increment, which this
// integrates exactly; q and the last s_e are carried with the increment's rotation (polar part of f), so
// the update stays objective. Relaxation acts after the return mapping: it lowers a stress below yield and
// never raises one, and its dissipation shows as internal work (the solver's energy balance integrates
// the stress power).
struct MaterialPoint {
  Eigen::Matrix3d elastic_left_cauchy_green = Eigen::Matrix3d::Identity();  // b_e
  double plastic_strain = 0.0;
  Eigen::Matrix3d relaxed_stress_MPa = Eigen::Matrix3d::Zero();      // q (viscoelastic only)
  Eigen::Matrix3d elastic_deviator_MPa = Eigen::Matrix3d::Zero();    // s_e of the last update (viscoelastic only)
};

struct StressUpdate {
  MaterialPoint state;
  Eigen::Matrix3d cauchy_stress_MPa;
  bool rate_factor_capped;
  // Total effective strain: eps_p + the von Mises equivalent of the elastic log strain,
  // sqrt(2/3 dev(h):dev(h)). In uniaxial tension of the plastically incompressible card this is the
  // true strain of the tensile test (up to the elastic part's compressibility), the measure in which
  // the paper gives its rupture strain (1.84).
  double effective_strain;
};

// One increment with relative deformation gradient f = F_n+1 F_n^-1 over dt_ms (> 0 gives the strain
// rate of the rate law, from the deviatoric part of ln(f f^T) / 2).
// Where the trial b_e = f b_e f^T lies near the identity (hencky_strain.h) and the law stays elastic, the update
// works with h as a matrix and needs no eigenvalues; elsewhere it works in h's principal axes
// (update_stress_by_eigenvalues), as a law that flows must. The two agree to rounding.
StressUpdate update_stress(const TissueMaterial& material, const MaterialPoint& state, const Eigen::Matrix3d& relative_F,
                           double dt_ms);
// The same update, always in the principal axes of the trial's eigenvalue problem (for tests).
StressUpdate update_stress_by_eigenvalues(const TissueMaterial& material, const MaterialPoint& state, const Eigen::Matrix3d& relative_F,
                                          double dt_ms);

// Crushed material (the lip release's kParticleCrushed, solver/separation/lip_release.h): the update's Cauchy stress and
// elastic b_e keep only their volumetric parts, so no shear stress is stored to come back at the next update, and a
// viscoelastic point's Maxwell stresses are cleared.
void keep_pressure_only(StressUpdate& update);

// The closed-form uniaxial curve of the card: Cauchy (true) stress at a true (log) strain pulled at a
// constant true strain rate (elastic to the rate-scaled yield, then on sigma_y(eps - sigma / E)). A scalar
// equation solved by bisection; independent of update_stress, for tests and plots.
double uniaxial_true_stress_MPa(const TissueMaterial& material, double true_strain, double strain_rate_per_ms);

}  // namespace needle
