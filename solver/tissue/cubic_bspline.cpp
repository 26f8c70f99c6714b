#include "solver/tissue/cubic_bspline.h"

namespace needle {

double cubic_bspline(double z) {
  if (z < 0) z = -z;
  if (z <= 0.5) return 2.0 / 3.0 - 4.0 * z * z + 4.0 * z * z * z;
  if (z <= 1.0) return 4.0 / 3.0 - 4.0 * z + 4.0 * z * z - 4.0 / 3.0 * z * z * z;
  return 0.0;
}

double cubic_bspline_derivative(double z) {
  const double sign = z < 0 ? -1.0 : 1.0;
  if (z < 0) z = -z;
  if (z <= 0.5) return sign * (-8.0 * z + 12.0 * z * z);
  if (z <= 1.0) return sign * (-4.0 + 8.0 * z - 4.0 * z * z);
  return 0.0;
}

}  // namespace needle
