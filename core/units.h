#pragma once
// Units: the project computes in mm, ms, g, N, MPa (and mm/ms = m/s, g/mm^3, deg); conversion happens once,
// at input. The units a value string may carry ("3 cm", "8 m/s", "193 GPa"), and the suffix a key carries
// its canonical unit in ("travel_mm", "speed_m_per_s", "E_MPa").
#include <string>
#include <vector>

namespace needle {

enum class Dimension { length, time, speed, stress, density, angle };

struct UnitSpec {
  const char* name;
  Dimension dimension;
  double to_internal;  // factor from this unit to the internal one
};

// Every unit understood: mm cm m um, ms s us, m/s mm/ms mm/s, MPa GPa kPa Pa, g/cm3 kg/m3 g/mm3, deg rad.
const std::vector<UnitSpec>& units();
// The unit of that name, or nullptr.
const UnitSpec* find_unit(const std::string& name);
// "a length (mm, cm, m, um)": what a dimension is, for messages.
const char* dimension_name(Dimension dimension);
// The canonical key suffix of a dimension ("_mm") and the factor from its unit to internal units.
std::string canonical_suffix(Dimension dimension);
double canonical_to_internal(Dimension dimension);
// An internal value in the canonical unit, chosen to read back as exactly that internal value: a plain
// division by the factor can land one ulp off (9 g/cm3 is 0.009 g/mm3, and 0.009 * 1e3 reads back as 9.000000000000002),
// so a stored scene would not read back as the scene it was written from. The nearest canonical value that
// reads back exactly; the plain quotient where none within a few ulps does (a value no input could give).
double internal_to_canonical(Dimension dimension, double internal);

}  // namespace needle
