#include <catch2/catch.hpp>

#include "runs/recipe_json.h"
#include "core/input_error.h"
#include "geometry/tip_geometry.h"

using namespace needle;
using nlohmann::json;

TEST_CASE("recipe JSON: a multi-bevel tip from d_a matches the factory", "[apps][recipe]") {
  const json j = json::parse(R"({
    "name": "my LMB",
    "tip": {"d_a_mm": -0.22},
    "grinds": [
      {"name": "top", "tilt_deg": 23.5, "rotation_deg": 0},
      {"name": "bottom", "tilt_deg": 12, "rotation_deg": 180},
      {"name": "side_pos", "tilt_deg": 12, "rotation_deg": 110},
      {"name": "side_neg", "tilt_deg": 12, "rotation_deg": -110}
    ]})");
  const TipGeometry a = resolve_tip(recipe_from_json(j, "test.json"));
  const TipGeometry b = resolve_tip(preset_recipe("LMB"));
  REQUIRE(a.facets.size() == b.facets.size());
  for (size_t i = 0; i < a.facets.size(); ++i) {
    CHECK((a.facets[i].normal - b.facets[i].normal).norm() < 1e-15);
    CHECK((a.facets[i].point - b.facets[i].point).norm() < 1e-15);
  }
  // Round trip through recipe_to_json.
  const TipGeometry c = resolve_tip(recipe_from_json(recipe_to_json(recipe_from_json(j, "t")), "t"));
  CHECK((c.tip_point - a.tip_point).norm() < 1e-15);
}

TEST_CASE("recipe JSON: unknown keys and wrong types name the key", "[apps][recipe][errors]") {
  CHECK_THROWS_WITH(recipe_from_json(json::parse(R"({"preset": "SB", "rod": {"diameter": 1}})"), "r.json"),
                    Catch::Contains("unknown key 'rod.diameter'"));
  CHECK_THROWS_WITH(recipe_from_json(json::parse(R"({"preset": "SB", "grinds": [{"name": "a", "tilt_deg": "x"}]})"), "r.json"),
                    Catch::Contains("'grinds[0].tilt_deg' must be a number"));
  CHECK_THROWS_WITH(recipe_from_json(json::parse(R"({"preset": "ZZ"})"), "r.json"), Catch::Contains("unknown preset"));
  CHECK_THROWS_WITH(read_recipe_file("/nonexistent/recipe.json"), Catch::Contains("no such file"));
}
