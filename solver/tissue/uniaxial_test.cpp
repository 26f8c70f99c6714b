#include "solver/tissue/uniaxial_test.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <fmt/format.h>

#include "core/input_error.h"
#include "mesher/particle_lattice.h"
#include "solver/tissue/tissue_dynamics.h"
#include "solver/tissue/spg_tissue.h"

namespace needle {

void UniaxialTestOptions::validate() const {
  for (auto [value, name] : {std::pair{length_mm, "length_mm"}, {width_mm, "width_mm"}, {thickness_mm, "thickness_mm"},
                             {spacing_mm, "spacing_mm"}, {max_strain, "max_strain"}, {strain_rate_per_ms, "strain_rate_per_ms"}})
    NEEDLE_REQUIRE(std::isfinite(value) && value > 0, fmt::format("material test {} must be positive (got {})", name, value));
  NEEDLE_REQUIRE(max_strain <= 3.0, fmt::format("material test max_strain {} is beyond 3 (a stretch of 20)", max_strain));
  NEEDLE_REQUIRE(spacing_mm <= 0.5 * std::min(width_mm, thickness_mm),
                 "material test spacing must leave at least 3 particles across the specimen");
  NEEDLE_REQUIRE(length_mm / spacing_mm <= 2000 && width_mm / spacing_mm <= 200 && thickness_mm / spacing_mm <= 200,
                 "material test spacing too fine for the specimen");
  NEEDLE_REQUIRE(samples >= 2 && samples <= 10000, "material test samples must lie in [2, 10000]");
  spg.validate();
}

double UniaxialCurve::max_relative_error() const {
  double scale = 0, worst = 0;
  for (double s : closed_form_stress_MPa) scale = std::max(scale, std::abs(s));
  for (size_t k = 0; k < true_stress_MPa.size(); ++k)
    worst = std::max(worst, std::abs(true_stress_MPa[k] - closed_form_stress_MPa[k]));
  return scale > 0 ? worst / scale : worst;
}

UniaxialCurve run_uniaxial_test(const TissueMaterial& material, const UniaxialTestOptions& o) {
  o.validate();
  material.validate();
  const auto start = std::chrono::steady_clock::now();
  TissueBox box;
  box.min_mm = {0, -0.5 * o.width_mm, -0.5 * o.thickness_mm};
  box.max_mm = {o.length_mm, 0.5 * o.width_mm, 0.5 * o.thickness_mm};
  box.faces.fill(FaceCondition::free);
  LatticeOptions lattice;
  lattice.spacing_mm = o.spacing_mm;
  const ParticleSet set = make_particle_lattice(box, lattice);
  SpgTissue tissue(set, material, o.spg);
  TissueParticles& p = tissue.particles();
  const std::int64_t n = p.size();

  std::vector<std::int32_t> left, right;
  std::vector<std::int32_t> middle;  // middle third, for particle averages
  const double tol = 1e-9 * o.length_mm;
  for (std::int64_t i = 0; i < n; ++i) {
    const double x = p.reference_mm[static_cast<size_t>(i)].x();
    if (x < tol) left.push_back(static_cast<std::int32_t>(i));
    if (x > o.length_mm - tol) right.push_back(static_cast<std::int32_t>(i));
    if (std::abs(x - 0.5 * o.length_mm) <= o.length_mm / 6.0) middle.push_back(static_cast<std::int32_t>(i));
  }
  // Mid-length cross-section: the lattice plane nearest to L/2.
  double mid_x = 0, best = 1e300;
  for (std::int64_t i = 0; i < n; ++i) {
    const double d = std::abs(p.reference_mm[static_cast<size_t>(i)].x() - 0.5 * o.length_mm);
    if (d < best) best = d, mid_x = p.reference_mm[static_cast<size_t>(i)].x();
  }
  std::vector<std::int32_t> section;
  for (std::int64_t i = 0; i < n; ++i)
    if (std::abs(p.reference_mm[static_cast<size_t>(i)].x() - mid_x) < tol) section.push_back(static_cast<std::int32_t>(i));

  // Grips move at -+ rate L(t) / 2 with L(t) = L0 exp(rate t); the body starts with the matching field.
  const double rate = o.strain_rate_per_ms, L0 = o.length_mm;
  auto grip_speed = [rate, L0](double t) { return 0.5 * rate * L0 * std::exp(rate * t); };
  for (std::int64_t i = 0; i < n; ++i)
    p.velocity_mm_per_ms[static_cast<size_t>(i)] = Vec3d(rate * (p.reference_mm[static_cast<size_t>(i)].x() - 0.5 * L0), 0, 0);
  std::vector<VelocityConstraint> constraints{{left, 0, [grip_speed](double t) { return -grip_speed(t); }, {}},
                                              {right, 0, grip_speed, {}}};
  // Guided lateral faces: y_i(t) = y_i(0) stretch(t), with d ln(stretch)/dt set by the servo below.
  struct LateralServo {
    double stretch = 1.0, log_rate_per_ms = 0.0;
  };
  auto servo = std::make_shared<LateralServo>();
  const double lambda_lame = material.lame_lambda_MPa(), mu = material.shear_modulus_MPa();
  servo->log_rate_per_ms = -lambda_lame / (2 * (lambda_lame + mu)) * rate;  // elastic start: -nu rate
  if (o.guided_lateral) {
    std::vector<std::int32_t> all(static_cast<size_t>(n));
    std::vector<double> y0(static_cast<size_t>(n)), z0(static_cast<size_t>(n));
    for (std::int64_t i = 0; i < n; ++i) {
      all[static_cast<size_t>(i)] = static_cast<std::int32_t>(i);
      y0[static_cast<size_t>(i)] = p.reference_mm[static_cast<size_t>(i)].y();
      z0[static_cast<size_t>(i)] = p.reference_mm[static_cast<size_t>(i)].z();
      p.velocity_mm_per_ms[static_cast<size_t>(i)].y() = servo->log_rate_per_ms * y0[static_cast<size_t>(i)];
      p.velocity_mm_per_ms[static_cast<size_t>(i)].z() = servo->log_rate_per_ms * z0[static_cast<size_t>(i)];
    }
    auto lateral_speed = [servo](double) { return servo->log_rate_per_ms * servo->stretch; };
    constraints.push_back({all, 1, lateral_speed, y0});
    constraints.push_back({all, 2, lateral_speed, z0});
  } else {
    for (std::int64_t i = 0; i < n; ++i) {
      p.velocity_mm_per_ms[static_cast<size_t>(i)].y() = servo->log_rate_per_ms * p.reference_mm[static_cast<size_t>(i)].y();
      p.velocity_mm_per_ms[static_cast<size_t>(i)].z() = servo->log_rate_per_ms * p.reference_mm[static_cast<size_t>(i)].z();
    }
  }
  TissueDynamics dynamics(tissue, constraints);
  auto mean_lateral_stress = [&]() {
    double sum = 0;
    for (std::int32_t i : middle)
      sum += 0.5 * (p.stress_MPa[static_cast<size_t>(i)](1, 1) + p.stress_MPa[static_cast<size_t>(i)](2, 2));
    return sum / static_cast<double>(middle.size());
  };

  UniaxialCurve curve;
  curve.particles = n;
  curve.neighbours = tissue.shape_functions().entries();
  const double area0 = o.width_mm * o.thickness_mm;
  auto extent = [&](int axis) {
    double lo = 1e300, hi = -1e300;
    for (std::int32_t i : section) {
      lo = std::min(lo, p.position_mm[static_cast<size_t>(i)][axis]);
      hi = std::max(hi, p.position_mm[static_cast<size_t>(i)][axis]);
    }
    return hi - lo;
  };
  const double width0 = extent(1), thickness0 = extent(2);
  auto record = [&]() {
    const double length = p.position_mm[static_cast<size_t>(right.front())].x() - p.position_mm[static_cast<size_t>(left.front())].x();
    const double strain = std::log(length / L0);
    const double area = area0 * (extent(1) / width0) * (extent(2) / thickness0);
    const double force = 0.5 * (-dynamics.constraint_internal_force_N(1).x() + dynamics.constraint_internal_force_N(0).x());
    curve.lateral_stress_MPa.push_back(mean_lateral_stress());
    double sxx = 0, ep = 0;
    for (std::int32_t i : middle) {
      sxx += p.stress_MPa[static_cast<size_t>(i)](0, 0);
      ep += p.plastic_strain[static_cast<size_t>(i)];
    }
    curve.true_strain.push_back(strain);
    curve.true_stress_MPa.push_back(force / area);
    curve.particle_stress_MPa.push_back(sxx / static_cast<double>(middle.size()));
    curve.plastic_strain.push_back(ep / static_cast<double>(middle.size()));
    curve.closed_form_stress_MPa.push_back(uniaxial_true_stress_MPa(material, strain, rate));
  };
  record();
  const double end_time = o.max_strain / rate;
  double previous_dt_ms = 0;
  for (int k = 1; k < o.samples; ++k) {
    const double sample_time = end_time * k / (o.samples - 1);
    while (dynamics.time_ms() < sample_time - 1e-12 * end_time) {
      const StepReport step = dynamics.step(sample_time - dynamics.time_ms());
      if (o.guided_lateral) {
        // Servo: the lateral log-strain rate that would cancel the mean lateral stress over the next
        // step through the elastic response (lateral stiffness 2 (lambda + mu)), relaxed by half.
        // The tangent's constants, which a stiffening law raises as it stiffens (the elastic ones for MAT_018).
        const double mu_t = material.tangent_shear_modulus_MPa(rate * dynamics.time_ms());
        const double lambda_t = material.bulk_modulus_MPa() - 2.0 / 3.0 * mu_t;
        servo->stretch *= std::exp(servo->log_rate_per_ms * step.dt_ms);
        // A step cut short to land on a sample would divide the correction by a tiny dt: keep the rate.
        if (step.dt_ms >= 0.5 * previous_dt_ms)
          servo->log_rate_per_ms = -(lambda_t * rate + 0.5 * mean_lateral_stress() / step.dt_ms) / (2 * (lambda_t + mu_t));
      }
      previous_dt_ms = step.dt_ms;
      curve.rate_factor_capped += step.rate_factor_capped;
      curve.max_energy_error = std::max(curve.max_energy_error, dynamics.energy().relative_error());
    }
    record();
  }
  curve.steps = dynamics.steps();
  curve.bonds_broken = tissue.bonds().broken_count;
  curve.runtime_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return curve;
}

}  // namespace needle
