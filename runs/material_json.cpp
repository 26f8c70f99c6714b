#include "runs/material_json.h"

#include <fstream>

#include "runs/json_object_reader.h"
#include "runs/json_file.h"
#include "core/input_file.h"

namespace needle {

TissueMaterial material_from_json(const nlohmann::json& json, const std::string& source, const TissueMaterial& defaults) {
  ObjectReader reader(json, "material", source);
  TissueMaterial m = defaults;
  m.law = tissue_law_from_name(reader.text("law", tissue_law_name(m.law)));
  m.E_MPa = reader.number("E_MPa", m.E_MPa);
  m.nu = reader.number("nu", m.nu);
  m.density_g_per_cm3 = reader.number("density_g_per_cm3", m.density_g_per_cm3);
  m.k_MPa = reader.number("k_MPa", m.k_MPa);
  m.n = reader.number("n", m.n);
  m.rate_law = rate_law_from_name(reader.text("rate_law", rate_law_name(m.rate_law)));
  m.rate_C_per_ms = reader.number("rate_C_per_ms", m.rate_C_per_ms);
  m.rate_p = reader.number("rate_p", m.rate_p);
  m.max_rate_factor = reader.number("max_rate_factor", m.max_rate_factor);
  m.relaxing_shear_fraction = reader.number("relaxing_shear_fraction", m.relaxing_shear_fraction);
  m.relaxation_time_ms = reader.number("relaxation_time_ms", m.relaxation_time_ms);
  reader.finish();
  return m;
}

TissueMaterial read_material_file(const std::string& path) {
  check_input_file(path, "material file");
  std::ifstream in(path);
  NEEDLE_REQUIRE(in, fmt::format("cannot read material file '{}'", path));
  nlohmann::json json;
  try {
    json = parse_json_refusing_duplicates(in, path);
  } catch (const nlohmann::json::exception& e) {  // a parse error, or a number too large (out_of_range)
    throw InputError(fmt::format("{}: not valid JSON ({})", path, json_error_words(e)));
  }
  return material_from_json(json, path);
}

nlohmann::json material_to_json(const TissueMaterial& m) {
  nlohmann::json json = {{"E_MPa", m.E_MPa}, {"nu", m.nu}, {"density_g_per_cm3", m.density_g_per_cm3}, {"k_MPa", m.k_MPa}, {"n", m.n},
          {"rate_law", rate_law_name(m.rate_law)}, {"rate_C_per_ms", m.rate_C_per_ms}, {"rate_p", m.rate_p},
          {"max_rate_factor", m.max_rate_factor}};
  // The paper's card is the default and is not named, so scenes written before the law existed read back
  // the same (and their runs are reused).
  if (m.law != TissueLaw::mat018) json["law"] = tissue_law_name(m.law);
  // Likewise the card has no relaxation: the keys are written only for a viscoelastic tissue.
  if (m.viscoelastic()) {
    json["relaxing_shear_fraction"] = m.relaxing_shear_fraction;
    json["relaxation_time_ms"] = m.relaxation_time_ms;
  }
  return json;
}

}  // namespace needle
