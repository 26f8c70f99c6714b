#include "core/units.h"

#include <cmath>
#include <limits>

namespace needle {

// Units a value string may carry; internal units are mm, ms, mm/ms (= m/s), MPa, g/mm^3, deg.
const std::vector<UnitSpec>& units() {
  static const std::vector<UnitSpec> table = {
      {"mm", Dimension::length, 1.0},       {"cm", Dimension::length, 10.0},      {"m", Dimension::length, 1000.0},
      {"um", Dimension::length, 1e-3},      {"ms", Dimension::time, 1.0},         {"s", Dimension::time, 1000.0},
      {"us", Dimension::time, 1e-3},        {"m/s", Dimension::speed, 1.0},       {"mm/ms", Dimension::speed, 1.0},
      {"mm/s", Dimension::speed, 1e-3},     {"MPa", Dimension::stress, 1.0},      {"GPa", Dimension::stress, 1000.0},
      {"kPa", Dimension::stress, 1e-3},     {"Pa", Dimension::stress, 1e-6},      {"g/cm3", Dimension::density, 1e-3},
      {"kg/m3", Dimension::density, 1e-6},  {"g/mm3", Dimension::density, 1.0},   {"deg", Dimension::angle, 1.0},
      {"rad", Dimension::angle, 180.0 / M_PI}};
  return table;
}

const char* dimension_name(Dimension d) {
  switch (d) {
    case Dimension::length: return "a length (mm, cm, m, um)";
    case Dimension::time: return "a time (ms, s, us)";
    case Dimension::speed: return "a speed (m/s, mm/ms, mm/s)";
    case Dimension::stress: return "a stress (MPa, GPa, kPa, Pa)";
    case Dimension::density: return "a density (g/cm3, kg/m3, g/mm3)";
    case Dimension::angle: return "an angle (deg, rad)";
  }
  return "";
}

const UnitSpec* find_unit(const std::string& name) {
  for (const UnitSpec& u : units())
    if (u.name == name) return &u;
  return nullptr;
}

std::string canonical_suffix(Dimension d) {
  switch (d) {
    case Dimension::length: return "_mm";
    case Dimension::time: return "_ms";
    case Dimension::speed: return "_m_per_s";
    case Dimension::stress: return "_MPa";
    case Dimension::density: return "_g_per_cm3";
    case Dimension::angle: return "_deg";
  }
  return "";
}

double canonical_to_internal(Dimension d) { return d == Dimension::density ? 1e-3 : 1.0; }

double internal_to_canonical(Dimension d, double internal) {
  const double factor = canonical_to_internal(d);
  const double quotient = internal / factor;
  if (!std::isfinite(quotient) || quotient * factor == internal) return quotient;
  // The reading multiplies by the factor, a monotone map: walk outwards from the quotient, nearest first.
  double below = quotient, above = quotient;
  for (int ulps = 1; ulps <= 8; ++ulps) {
    below = std::nextafter(below, -std::numeric_limits<double>::infinity());
    above = std::nextafter(above, std::numeric_limits<double>::infinity());
    if (above * factor == internal) return above;
    if (below * factor == internal) return below;
  }
  return quotient;
}

}  // namespace needle
