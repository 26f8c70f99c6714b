#include "solver/needle/needle_material.h"

#include <cmath>
#include <fmt/format.h>

#include "core/input_error.h"

namespace needle {

void NeedleMaterial::validate(const std::string& where) const {
  NEEDLE_REQUIRE(std::isfinite(youngs_modulus_MPa) && youngs_modulus_MPa > 0,
                 fmt::format("{}: youngs_modulus_MPa must be positive (got {})", where, youngs_modulus_MPa));
  NEEDLE_REQUIRE(std::isfinite(poisson_ratio) && poisson_ratio > -1.0 && poisson_ratio < 0.5,
                 fmt::format("{}: poisson_ratio must lie in (-1, 0.5) (got {})", where, poisson_ratio));
  NEEDLE_REQUIRE(std::isfinite(density_g_per_mm3) && density_g_per_mm3 > 0,
                 fmt::format("{}: density must be positive (got {} g/mm^3)", where, density_g_per_mm3));
}

}  // namespace needle
