#include "solver/tissue/spg_options.h"

#include <cmath>
#include <fmt/format.h>

#include "core/input_error.h"

namespace needle {

void SpgOptions::validate() const {
  NEEDLE_REQUIRE(std::isfinite(dilation) && dilation >= 1.0 && dilation <= 4.0,
                 fmt::format("SPG dilation must lie in [1, 4] particle spacings (got {}); below 1 a support misses its neighbours", dilation));
  NEEDLE_REQUIRE(kernel_update_interval_steps >= 1, "SPG kernel_update_interval_steps must be >= 1");
  NEEDLE_REQUIRE(std::isfinite(stabilization_coefficient) && stabilization_coefficient >= 0,
                 fmt::format("SPG stabilization coefficient must be >= 0 (got {})", stabilization_coefficient));
  NEEDLE_REQUIRE(stabilization != Stabilization::filter || stabilization_coefficient <= 1.0,
                 "SPG filter coefficient must lie in [0, 1]");
  NEEDLE_REQUIRE(smoothing_interval_steps >= 1, "SPG smoothing_interval_steps must be >= 1");
  NEEDLE_REQUIRE(std::isfinite(crack_face_min_volume_ratio) && crack_face_min_volume_ratio >= 0 && crack_face_min_volume_ratio < 1,
                 fmt::format("SPG crack_face_min_volume_ratio must lie in [0, 1) (got {})", crack_face_min_volume_ratio));
  NEEDLE_REQUIRE(std::isfinite(bond_failure.strain) && bond_failure.strain > 0,
                 fmt::format("bond failure strain must be positive (got {})", bond_failure.strain));
  NEEDLE_REQUIRE(std::isfinite(bond_failure.stretch_ratio) && (bond_failure.stretch_ratio == 0 || bond_failure.stretch_ratio > 1),
                 fmt::format("bond failure stretch ratio must be 0 (off) or > 1 (got {})", bond_failure.stretch_ratio));
  NEEDLE_REQUIRE(std::isfinite(cfl) && cfl > 0 && cfl <= 1.0, fmt::format("CFL number must lie in (0, 1] (got {})", cfl));
}

KernelUpdate kernel_update_from_name(const std::string& name) {
  if (name == "lagrangian") return KernelUpdate::lagrangian;
  if (name == "reinitialized" || name == "eulerian") return KernelUpdate::reinitialized;
  throw InputError(fmt::format("kernel update '{}' is not one of lagrangian, reinitialized", name));
}
std::string kernel_update_name(KernelUpdate k) { return k == KernelUpdate::lagrangian ? "lagrangian" : "reinitialized"; }

FailureMeasure failure_measure_from_name(const std::string& name) {
  if (name == "effective" || name == "effective_strain") return FailureMeasure::effective_strain;
  if (name == "plastic" || name == "plastic_strain") return FailureMeasure::plastic_strain;
  throw InputError(fmt::format("bond failure measure '{}' is not one of effective, plastic", name));
}
std::string failure_measure_name(FailureMeasure m) { return m == FailureMeasure::plastic_strain ? "plastic" : "effective"; }

Stabilization stabilization_from_name(const std::string& name) {
  if (name == "none") return Stabilization::none;
  if (name == "penalty") return Stabilization::penalty;
  if (name == "filter") return Stabilization::filter;
  throw InputError(fmt::format("stabilization '{}' is not one of penalty, filter, none", name));
}
std::string stabilization_name(Stabilization s) {
  switch (s) {
    case Stabilization::none: return "none";
    case Stabilization::penalty: return "penalty";
    case Stabilization::filter: return "filter";
  }
  return "none";
}

}  // namespace needle
